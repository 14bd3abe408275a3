import os

import jax
import pytest

# the CLI's persistent compilation cache stays off in tests (hermetic; test_cli checks it on)
os.environ.setdefault("JAXCELT_CACHE_DIR", "off")

jax.config.update("jax_enable_x64", True)
jax.config.update("jax_numpy_rank_promotion", "raise")


@pytest.fixture(scope="session")
def paper_params():
    import jaxcelt

    return jaxcelt.CeltParams.paper()


@pytest.fixture(scope="session")
def kernel_cuda_text():
    """``f(cfg) -> str``: the lane kernel of ``cfg`` (omega_pi and q_pi varying) lowered for CUDA (Triton), as text.
    Lowering needs no GPU and fails on any operation Pallas' Triton backend cannot lower."""
    import jax.numpy as jnp
    import numpy as np

    import jaxcelt
    from jaxcelt.ensemble import BLOCK
    from jaxcelt.ensemble.kernel import KERNEL_FIELDS, make_segment

    p = jaxcelt.CeltParams.paper()
    leaves, treedef = jax.tree_util.tree_flatten(p)
    names = [path[-1].name for path, _ in jax.tree_util.tree_flatten_with_path(p)[0]]
    vary = [n in ("omega_pi", "q_pi") for n in names]
    consts = [np.asarray(x).item() for x in leaves]

    def params_of(pv):
        it = iter(pv)
        return jax.tree_util.tree_unflatten(treedef, [next(it) if v else c for v, c in zip(vary, consts)])

    def lower(cfg) -> str:
        seg = make_segment(cfg, params_of, 2)
        L = 2 * BLOCK
        z, zi = jnp.zeros(L), jnp.zeros(L, jnp.int32)
        ints = ("num_steps", "code", "first_invalid_kind", "stiff", "stiff_count", "stiff_steps")
        flat = [z] * 26 + [zi if k in ints else z for k in KERNEL_FIELDS]
        lowered = jax.jit(lambda flat, tg, pv: seg(flat, tg, tg, tg, pv, False)).trace(flat, z, (z, z))
        return lowered.lower(lowering_platforms=("cuda",)).as_text()

    return lower
