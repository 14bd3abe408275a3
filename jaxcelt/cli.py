"""Command line: ``jaxcelt <command> ...`` (also ``python -m jaxcelt``).

A thin layer: each command lives in `jaxcelt.commands.<name>` with ``register(subparsers)``
adding its parser and a ``func(args) -> int``; the physics is in the library.
"""

from __future__ import annotations

import argparse
import importlib
import sys

# Each entry is a module in jaxcelt.commands exposing register(subparsers).
COMMANDS: tuple[str, ...] = ("simulate", "bifurcation", "fit", "ladder", "map")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="jaxcelt", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="store_true", help="print package and JAX versions and exit")
    sub = parser.add_subparsers(dest="command")
    for name in COMMANDS:
        importlib.import_module(f"jaxcelt.commands.{name}").register(sub)
    return parser


def _enable_compile_cache() -> None:
    """Persistent XLA compilation cache for the command line (a rerun or a resumed sweep skips
    the compile). Directory: $JAXCELT_CACHE_DIR, default ~/.cache/jaxcelt/xla; "off" disables."""
    import os

    import jax

    d = os.environ.get("JAXCELT_CACHE_DIR", os.path.join(os.path.expanduser("~"), ".cache", "jaxcelt", "xla"))
    if d.strip().lower() in ("", "0", "off", "none"):
        return
    jax.config.update("jax_compilation_cache_dir", d)
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 1.0)


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    _enable_compile_cache()
    if args.version:
        from .versions import versions_string

        print(versions_string())
        return 0
    if args.command is None:
        parser.print_help()
        return 2
    return int(args.func(args) or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
