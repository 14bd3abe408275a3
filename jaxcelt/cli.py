"""Command line: ``jaxcelt <command> ...`` (also ``python -m jaxcelt``).

A thin layer: each command lives in `jaxcelt.commands.<name>` with ``register(subparsers)``
adding its parser and a ``func(args) -> int``; the physics is in the library.

Bad input is reported in one place: an argparse error, or a ``ValueError`` raised while a
command checks its input (the library names the parameter), prints one line
``jaxcelt <command>: error: <message>`` to stderr and exits with status 2. Set
``JAXCELT_TRACEBACK=1`` to see the traceback instead.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

# Each entry is a module in jaxcelt.commands exposing register(subparsers).
COMMANDS: tuple[str, ...] = ("simulate", "bifurcation", "fit", "ladder", "map", "orbits", "atlas")


class OneLineParser(argparse.ArgumentParser):
    """An `argparse.ArgumentParser` whose errors are one line, ``<prog>: error: <message>``, on
    stderr, exit status 2 (argparse's default also prints the usage block). Subparsers inherit it."""

    def error(self, message: str):  # type: ignore[override]
        one_line = " ".join(str(message).split())
        self.exit(2, f"{self.prog}: error: {one_line}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(prog="jaxcelt", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="store_true", help="print package and JAX versions and exit")
    sub = parser.add_subparsers(dest="command")
    for name in COMMANDS:
        importlib.import_module(f"jaxcelt.commands.{name}").register(sub)
    for command_parser in sub.choices.values():  # main() reports a command's ValueError through its parser
        command_parser.set_defaults(command_parser=command_parser)
    return parser


def _enable_compile_cache() -> None:
    """Persistent XLA compilation cache for the command line (a rerun or a resumed sweep skips
    the compile). Directory: $JAXCELT_CACHE_DIR, default ~/.cache/jaxcelt/xla; "off" disables.
    Programs that compile in under a second are not stored unless JAX's own
    $JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS says otherwise."""
    import jax

    d = os.environ.get("JAXCELT_CACHE_DIR", os.path.join(os.path.expanduser("~"), ".cache", "jaxcelt", "xla"))
    if d.strip().lower() in ("", "0", "off", "none"):
        return
    jax.config.update("jax_compilation_cache_dir", d)
    if "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS" not in os.environ:
        jax.config.update("jax_persistent_cache_min_compile_time_secs", 1.0)


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    _enable_compile_cache()
    if args.version:
        from jaxcelt.versions import versions_string

        print(versions_string())
        return 0
    if args.command is None:
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except ValueError as e:  # bad input found while the command checks it (the message names the parameter)
        if os.environ.get("JAXCELT_TRACEBACK", "").strip() not in ("", "0"):
            raise
        args.command_parser.error(str(e))
        raise  # pragma: no cover  (error() exits)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
