"""Versions of jaxcelt and the numerical stack, printed with every benchmark and stored in datasets."""

from __future__ import annotations

import importlib.metadata
import platform


def versions() -> dict[str, str]:
    out = {}
    for pkg in ("jaxcelt", "jax", "jaxlib", "diffrax", "equinox", "optimistix", "optax", "numpy"):
        try:
            out[pkg] = importlib.metadata.version(pkg)
        except importlib.metadata.PackageNotFoundError:
            out[pkg] = "not installed"
    import jax

    out["jax_backend"] = jax.default_backend()
    out["devices"] = ", ".join(str(d) for d in jax.devices())
    out["python"] = platform.python_version()
    out["machine"] = f"{platform.machine()} {platform.processor() or ''}".strip()
    return out


def versions_string() -> str:
    return " ".join(f"{k}={v}" for k, v in versions().items())
