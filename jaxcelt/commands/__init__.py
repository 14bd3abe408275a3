"""CLI commands; each module exposes ``register(subparsers)``. See `jaxcelt.cli`."""
