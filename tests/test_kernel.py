"""The lane kernel (`jaxcelt.ensemble.kernel`) and the blockwise transform it rests on (`jaxcelt.ensemble.soa`).

On a CPU the kernel runs in Pallas' interpreter: the same algorithm, not the compiled GPU
program. That the GPU program can be built is checked by lowering it for CUDA (Triton), which
needs no GPU; that it agrees with the pool on a GPU is measured by ``benchmarks/gpu_map.py --check``.
"""

from __future__ import annotations

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcelt as jc
from jaxcelt.ensemble import BLOCK, SweepConfig, blockwise, lanes_params, run_lanes
from jaxcelt.ensemble.kernel import make_segment
from jaxcelt.ensemble.soa import as_blocks, from_blocks
from jaxcelt.physics.contact.registry import get_contact_law
from jaxcelt.physics.model import vector_field_and_normal

P = jc.CeltParams.paper()
LAW = get_contact_law(None)


def _grid_lanes(n: int = 4):
    """n x n cheap lanes (omega_pi 15-20 rad/s, q_pi 0.04-0.06 m: no sticking), from rest."""
    xs, ys = np.linspace(15.0, 20.0, n), np.linspace(0.04, 0.06, n)
    pb = eqx.tree_at(lambda q: q.q_pi, lanes_params(P, "omega_pi", np.repeat(xs, n)), jnp.asarray(np.tile(ys, n)))
    return pb, np.tile(np.asarray(jc.initial_state(P)), (n * n, 1))


def _field(t, y, om, q):
    return vector_field_and_normal(t, y, eqx.tree_at(lambda r: (r.omega_pi, r.q_pi), P, (om, q)), LAW)


def test_blockwise_field_equals_vmap():
    # the same arithmetic up to the order of the written-out sums: 1e-13 of the largest entry
    # (measured 2e-16)
    B = 16
    rng = np.random.default_rng(0)
    Y = np.asarray(jc.initial_state(P))[None, :] + 0.05 * rng.standard_normal((B, 13))
    Y[:, 6:9] /= np.linalg.norm(Y[:, 6:9], axis=1, keepdims=True)
    T, om, q = np.linspace(0, 1, B), np.linspace(10, 20, B), np.linspace(0.02, 0.06, B)
    g = blockwise(_field, 0.0, Y[0], 1.0, 1.0)

    @jax.jit
    def soa(T, Y, om, q):
        return jax.tree_util.tree_map(lambda o: from_blocks(o, B, jnp.float64), g(T, as_blocks(Y), om, q))

    got, ref = soa(T, Y, om, q), jax.vmap(_field)(T, Y, om, q)
    for a, b in zip(jax.tree_util.tree_leaves(got), jax.tree_util.tree_leaves(ref)):
        assert np.max(np.abs(np.asarray(a) - np.asarray(b))) <= 1e-13 * np.max(np.abs(np.asarray(b)))


def test_blockwise_folds_shared_numbers_and_names_unsupported_primitives():
    g = blockwise(lambda x, c: (x * c, jnp.sqrt(c) + 1.0), 1.0, 4.0)
    xb = jnp.arange(3.0)
    prod, folded = g(xb, np.float64(4.0))
    assert np.ndim(prod[()]) == 1 and np.allclose(prod[()], 4.0 * np.arange(3.0))
    assert isinstance(folded[()], np.ndarray) and float(folded[()]) == 3.0  # computed at trace time
    loop = blockwise(lambda x: jax.lax.while_loop(lambda v: v < 10.0, lambda v: v * 2.0, x), 1.0)
    with pytest.raises(NotImplementedError, match="while"):
        loop(xb)


def test_kernel_equals_pool_float64():
    # Two programs: the kernel (interpreted here) and the pool. Same algorithm, sums in another
    # order, so equal statuses and step counts within 1 % (measured equal), samples within 1e-7 of
    # max(|x|, 1e-3) (measured 3e-11: both at rtol 1e-8 over 5 periods of non-chaotic lanes).
    pb, y0 = _grid_lanes()
    cfg = SweepConfig(transient_periods=2, sample_periods=3, stop_on_invalid=True)
    a = run_lanes(pb, y0, cfg, engine="pool")
    b = run_lanes(pb, y0, cfg, engine="kernel")
    # statuses: two programs, so a lane near a boundary could flip; allow one of 16 (measured: none)
    same = a["status"] == b["status"]
    assert same.sum() >= len(same) - 1
    steps_close = np.abs(a["num_steps"] - b["num_steps"]) <= np.maximum(2, 0.01 * a["num_steps"])
    assert np.all(steps_close[same])
    fin = np.isfinite(a["samples"]) & np.isfinite(b["samples"]) & same[:, None, None]
    assert np.all(np.isfinite(b["samples"][b["status"] == 0]))
    diff = np.abs(np.where(fin, a["samples"] - b["samples"], 0.0))
    assert np.all(diff <= 1e-7 * np.maximum(np.abs(np.where(fin, a["samples"], 0.0)), 1e-3))
    np.testing.assert_allclose(a["t_samples"], b["t_samples"], rtol=1e-15)
    # the kernel's statistics: every lane's block steps at least as often as the lane
    assert b["pool_width"][0] == BLOCK
    assert b["pool_iterations"][0] >= b["num_steps"].max()
    assert b["pool_slot_steps"][0] >= b["num_steps"].sum()


def test_kernel_float32_follows_float64():
    # float32 state at rtol 1e-6 against the float64 kernel at 1e-8: every lane completes (times
    # are float64 in the kernel) and the samples agree to 1e-2 of max(|x|, 1e-2) (measured 5e-4:
    # float32 accuracy compounded over 5 periods)
    pb, y0 = _grid_lanes()
    kw = dict(transient_periods=2, sample_periods=3, stop_on_invalid=True)
    a = run_lanes(pb, y0, SweepConfig(**kw), engine="kernel")
    b = run_lanes(pb, y0, SweepConfig(rtol=1e-6, atol=1e-8, dtype="float32", **kw), engine="kernel")
    assert np.sum(b["status"] == a["status"]) >= len(a["status"]) - 1  # two programs: one may flip (measured: none)
    both = (b["status"] == a["status"])[:, None, None] & np.isfinite(a["samples"]) & np.isfinite(b["samples"])
    assert both.any()
    assert np.all(np.where(both, np.abs(b["samples"] - a["samples"]) <= 1e-2 * np.maximum(np.abs(a["samples"]), 1e-2), True))


def test_float32_field_time_keeps_the_forcing_phase():
    # t = 120 s: float32 resolves t to 7.6e-6 s, the reduced time to ~2e-8 s (one period ~0.36 s)
    om = 17.3
    params_of = lambda pv: P.replace(omega_pi=om)  # noqa: E731
    seg = make_segment(SweepConfig(dtype="float32"), params_of, 0)
    t = jnp.asarray([120.0, 120.123456789, 250.5], jnp.float64)
    tau = seg.field_time(t, ())
    assert tau.dtype == jnp.float32
    np.testing.assert_allclose(np.sin(om * np.asarray(tau, np.float64)), np.sin(om * np.asarray(t)), atol=2e-6)


def test_kernel_lowers_for_cuda_without_a_gpu(kernel_cuda_text):
    # the kernel is built for a GPU by Pallas' Triton backend; lowering it needs no GPU and fails
    # on any operation that backend cannot lower
    assert "triton" in kernel_cuda_text(SweepConfig(stop_on_invalid=True))


def test_engine_is_checked():
    with pytest.raises(ValueError, match="engine"):
        jc.bifurcation(P, [15.0], transient_periods=1, sample_periods=1, engine="gpu")
    with pytest.raises(ValueError, match="Kvaerno5"):
        jc.bifurcation(P, [15.0], transient_periods=1, sample_periods=1, engine="kernel", solver=diffrax.Kvaerno5())
