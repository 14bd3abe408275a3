"""MuJoCo (C) and MJX peers: the same stone as an ellipsoid on a plane, condim 6.

A *different contact model*: MuJoCo resolves a single soft contact point per step (convex
collision, soft constraint with solref/solimp, elliptic friction cone with sliding, torsional and
rolling coefficients), time-stepped with a fixed dt (semi-implicit Euler by default). jaxcelt
integrates the paper's smooth contact-patch law (MODEL.md section 7) with an adaptive solver. So
there is no equal-accuracy ratio: we compare cost per simulated second and qualitative behaviour.

Model built from `jaxcelt.CeltParams.paper()`:

* body frame at the mass centre C, axes = the ellipsoid's (x1 long, x3 up at rest); inertia
  ``fullinertia = (B1, B2, B3, -B12, -B13, -B23)`` (MODEL.md section 8's tensor, so the stone is a
  rattleback); the ellipsoid geom (a1, a2, a3) centred at O = C - k (4.29 mm above C);
* friction ``(mu, mu a_hat 4 E S2, a_hat pi S3 k_r)``: sliding = mu; torsional = the paper's
  pure-spin moment per unit N (mu a_hat 4 E S2 = 0.65 mm); rolling = its saturated
  rolling-resistance moment per unit N (a_hat pi S3 k_r = 0.50 mm); elliptic cone;
* vibrating base: simulated in the base frame, which accelerates with a_pi(t) = s q_pi omega_pi^2
  cos(omega_pi t) along X1 (derivative of eq. 17); the inertial force -m a_pi(t) is applied at C by
  a motor on the free joint's x dof (ctrl = that force), so `mujoco.rollout` runs it in C.

Scenes: the paper's from-rest scene (omega_pi = 17, 20 periods) and the classic rattleback test on
a fixed table: spin the "wrong" way, omega = (0, 2, -10) rad/s, and the "right" way, (0, 2, +10),
2.5 s each. Output (``--parts scenes``): ``mujoco.json``, ``mujoco.png`` (omega_s = omega . n and
tilt against time, MuJoCo vs jaxcelt); (``--parts mjx``): ``mujoco_mjx.json``, MJX
``jit(vmap(scan(mjx.step)))`` over lanes, compile and run time apart.

    python benchmarks/mujoco_peer.py [--out docs/performance] [--parts scenes,mjx] [--mjx-lanes 1,16,64,256] [--budget 600]
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time

import jax
import jax.numpy as jnp
import mujoco
import numpy as np
from mujoco import rollout

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import jaxcelt as jc  # noqa: E402
from jaxcelt.provenance import load_average, write_result  # noqa: E402
from jaxcelt.studies import benchmarking as bm  # noqa: E402
from jaxcelt.versions import versions  # noqa: E402

jax.config.update("jax_enable_x64", True)


def friction(p) -> tuple[float, float, float]:
    """(sliding, torsional [m], rolling [m]) resembling the paper's law (see module docstring)."""
    _, E, _, _ = jc.contact_integrals(p.b)
    mu, ah = float(p.mu), float(p.a_hat)
    return mu, mu * ah * 4 * float(E) * float(p.S2), ah * np.pi * float(p.S3) * float(p.k_r)


def mjcf(p, timestep: float = 0.002, integrator: str = "Euler") -> str:
    d = {k: float(np.asarray(v)) for k, v in p.as_dict().items() if np.ndim(v) == 0}
    fr = " ".join(f"{x:.6g}" for x in friction(p))
    o = (-d["k1"], -d["k2"], -d["k3"])  # O relative to C
    h = d["a3"] + d["k3"]  # height of C above the plane at rest (O at a3)
    return f"""
<mujoco model="wobblestone">
  <option timestep="{timestep}" integrator="{integrator}" cone="elliptic" gravity="0 0 {-d["g"]}"/>
  <worldbody>
    <geom name="base" type="plane" size="2 2 0.01" condim="6" friction="{fr}"/>
    <body name="stone" pos="0 0 {h:.9g}">
      <freejoint name="free"/>
      <inertial pos="0 0 0" mass="{d["m"]}" fullinertia="{d["B1"]} {d["B2"]} {d["B3"]} {-d["B12"]} {-d["B13"]} {-d["B23"]}"/>
      <geom name="stone" type="ellipsoid" size="{d["a1"]} {d["a2"]} {d["a3"]}" pos="{o[0]} {o[1]} {o[2]}"
            condim="6" friction="{fr}"/>
    </body>
  </worldbody>
  <actuator>
    <motor name="inertial_force_x" joint="free" gear="1 0 0 0 0 0" ctrllimited="false"/>
  </actuator>
</mujoco>"""


def initial_qpos_qvel(p, omega) -> tuple[np.ndarray, np.ndarray]:
    """Stone upright, contact point at rest: v_C = -omega x rho (body = world axes at t = 0)."""
    rho = np.array([0.0, 0.0, -float(p.a3)]) - np.array([float(p.k1), float(p.k2), float(p.k3)])
    w = np.asarray(omega, float)
    qpos = np.array([0.0, 0.0, -rho[2], 1.0, 0.0, 0.0, 0.0])
    qvel = np.concatenate([-np.cross(w, rho), w])  # linear (world), angular (local)
    return qpos, qvel


def base_force(p, t) -> np.ndarray:
    """-m a_pi(t): the inertial force in the base frame (a_pi = d/dt of eq. 17's v_pi)."""
    s, q, w, m = (float(p.v_pi_sign), float(p.q_pi), float(p.omega_pi), float(p.m))
    return -m * s * q * w * w * np.cos(w * np.asarray(t))


def spin_tilt(qpos, qvel):
    """omega_s = omega . n (vertical spin, rad/s) and tilt = arccos(n3) from MuJoCo states (..., 7), (..., 6)."""
    q = np.asarray(qpos)[..., 3:7]
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    # third row of the body->world rotation = n in body components
    n = np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1)
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    return np.sum(n * np.asarray(qvel)[..., 3:6], -1), np.arccos(np.clip(n[..., 2], -1, 1))


def run_mujoco(p, omega, T, timestep, integrator="Euler", repeats=3):
    """One trajectory through mujoco.rollout (C loop). Returns (t, omega_s, tilt, run_s, steps)."""
    m = mujoco.MjModel.from_xml_string(mjcf(p, timestep, integrator))
    d = mujoco.MjData(m)
    qpos, qvel = initial_qpos_qvel(p, omega)
    d.qpos[:], d.qvel[:] = qpos, qvel
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    x0 = np.empty(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, d, x0, spec)
    nstep = int(round(T / timestep))
    ctrl = base_force(p, np.arange(nstep) * timestep)[:, None]
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        state, _ = rollout.rollout(m, d, x0, ctrl)
        best = min(best, time.perf_counter() - t0)
    state = state[0]
    ws, tilt = spin_tilt(state[:, 1:8], state[:, 8:14])
    return state[:, 0], ws, tilt, best, nstep


def run_jaxcelt(p, omega, T, n_out=500, rtol=1e-8, repeats=2):
    y0 = jc.initial_state(p, omega=omega)
    ts = np.linspace(0, T, n_out + 1)

    def fn():
        return jc.simulate(p, y0, T, ts=ts, rtol=rtol, atol=rtol * 1e-2)

    sol, compile_s, run_s = bm.time_call(fn, repeats)
    ys = np.asarray(sol.ys)
    ws = np.sum(ys[:, 3:6] * ys[:, 6:9], -1)
    return ts, ws, np.arccos(np.clip(ys[:, 8], -1, 1)), run_s, compile_s, int(sol.num_accepted_steps)


def mjx_scaling(p, T, timestep, lanes_list, budget_s):
    """jit(vmap(scan(mjx.step))) over perturbed initial spins; compile and run time apart."""
    from mujoco import mjx

    m = mujoco.MjModel.from_xml_string(mjcf(p, timestep))
    mx = mjx.put_model(m)
    dx0 = mjx.make_data(mx)
    qpos, qvel = initial_qpos_qvel(p, (0.0, 0.0, 0.0))
    nstep = int(round(T / timestep))
    ctrl = jnp.asarray(base_force(p, np.arange(nstep) * timestep))

    def one(w):
        dx = dx0.replace(qpos=jnp.asarray(qpos), qvel=jnp.asarray(qvel).at[3:6].add(w))

        def step(dx, c):
            dx = mjx.step(mx, dx.replace(ctrl=jnp.reshape(c, (1,))))
            return dx, dx.qvel[5]

        dx, _ = jax.lax.scan(step, dx, ctrl)
        return dx.qpos, dx.qvel

    f = jax.jit(jax.vmap(one))
    rows, t_start = [], time.perf_counter()
    rng = np.random.default_rng(0)
    for L in lanes_list:
        if time.perf_counter() - t_start > budget_s:
            print(f"  MJX: budget spent, {L}+ lanes skipped", flush=True)
            break
        W = jnp.asarray(rng.normal(size=(L, 3)) * 0.05)
        t0 = time.perf_counter()
        jax.block_until_ready(f(W))
        first = time.perf_counter() - t0
        t0 = time.perf_counter()
        qp, qv = jax.block_until_ready(f(W))
        run = time.perf_counter() - t0
        ok = bool(np.all(np.isfinite(np.asarray(qp))))
        rows.append(dict(name=f"MJX dt {timestep:g}", lanes=L, run_s=run, compile_s=max(first - run, 0.0),
                         sim_s=T, steps=nstep, lanes_per_s=L / run, run_s_per_sim_s_per_lane=run / T / L, finite=ok))  # fmt: skip
        print(f"  MJX {L:5d} lanes: run {run:.2f}s compile {first - run:.1f}s -> {L * T / run:.2f} sim-s/s", flush=True)
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="docs/performance")
    ap.add_argument("--periods", type=int, default=20)
    ap.add_argument("--mjx-lanes", default="1,16,64,256")
    ap.add_argument("--mjx-periods", type=int, default=2)
    ap.add_argument("--budget", type=float, default=600.0, help="wall-second cap for the MJX scaling")
    ap.add_argument("--parts", default="scenes,mjx")
    args = ap.parse_args(argv)
    out = pathlib.Path(args.out)
    load0 = load_average()
    info = versions()
    info.update(device=bm.device_string(), mujoco=mujoco.__version__)
    try:
        import importlib.metadata as md

        info["mujoco_mjx"] = md.version("mujoco-mjx")
    except Exception:  # pragma: no cover
        pass
    print("versions:", info, flush=True)
    p17 = jc.CeltParams.paper(omega_pi=17.0)
    p_fix = jc.CeltParams.paper(q_pi=0.0)
    T17 = args.periods * 2 * np.pi / 17.0
    scenes = {
        "rest17": (p17, (0.0, 0.0, 0.0), T17, f"from rest, omega_pi = 17, {args.periods} periods ({T17:.2f} s)"),
        "spin_reversal": (p_fix, (0.0, 2.0, -10.0), 2.5, "fixed table, omega0 = (0, 2, -10) rad/s, 2.5 s"),
        "spin_right_way": (p_fix, (0.0, 2.0, 10.0), 2.5, "fixed table, omega0 = (0, 2, +10) rad/s, 2.5 s"),
    }
    parts = args.parts.split(",")
    res = dict(versions=info, friction=dict(zip(("sliding", "torsional_m", "rolling_m"), friction(p17))), scenes={})
    for key, (p, w0, T, desc) in scenes.items() if "scenes" in parts else ():
        print(f"{key}: {desc}", flush=True)
        t, ws, tilt, run_s, comp_s, steps = run_jaxcelt(p, w0, T, n_out=1000 if T > 5 else 500)
        sc = dict(description=desc, sim_s=T, runs=[])
        sc["runs"].append(dict(name="jaxcelt Tsit5 rtol 1e-8", run_s=run_s, compile_s=comp_s, steps=steps,
                               run_s_per_sim_s=run_s / T, **_trace(t, ws, tilt, 1)))  # fmt: skip
        print(f"  jaxcelt: {run_s * 1e3:.1f} ms ({steps} steps), omega_s end {ws[-1]:+.2f}", flush=True)
        for dt, integ in ((2e-3, "Euler"), (2e-4, "Euler"), (2e-3, "RK4")):
            t, ws, tilt, run_s, nstep = run_mujoco(p, w0, T, dt, integ)
            sc["runs"].append(dict(name=f"MuJoCo {integ} dt {dt:g}", run_s=run_s, steps=nstep, run_s_per_sim_s=run_s / T,
                                   finite=bool(np.all(np.isfinite(ws))), **_trace(t, ws, tilt, max(1, len(t) // 1000))))  # fmt: skip
            print(
                f"  MuJoCo {integ} dt {dt:g}: {run_s * 1e3:.1f} ms ({nstep} steps), omega_s end {ws[-1]:+.2f}",
                flush=True,
            )
        res["scenes"][key] = sc
    if "scenes" in parts:
        plot(res).savefig(out / "mujoco.png", dpi=110)
        for sc in res["scenes"].values():  # thin the traces in the JSON (the figure used them all)
            for r in sc["runs"]:
                k = -(-len(r["t"]) // 500)
                r.update({a: r[a][::k] for a in ("t", "omega_s", "tilt")})
        write_result(out / "mujoco.json", res, load_at_start=load0, indent=None, default=float)
    if "mjx" in parts:
        T_mjx = args.mjx_periods * 2 * np.pi / 17.0
        desc = f"rest17, {args.mjx_periods} periods ({T_mjx:.3f} s), dt 2e-3, initial spin + N(0, 0.05^2) rad/s"
        print(f"MJX scaling: {desc}", flush=True)
        mjx_rows = mjx_scaling(p17, T_mjx, 2e-3, [int(x) for x in args.mjx_lanes.split(",")], args.budget)
        write_result(out / "mujoco_mjx.json", dict(versions=info, scene=desc, mjx=mjx_rows), load_at_start=load0)
    return res


def _trace(t, ws, tilt, k):
    """Downsampled traces for the JSON (5 significant digits keep the file small)."""
    r = lambda a: [float(f"{x:.5g}") for x in np.asarray(a)[::k]]  # noqa: E731
    return dict(t=r(t), omega_s=r(ws), tilt=r(tilt))


def plot(res):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = list(res["scenes"])
    fig, axes = plt.subplots(2, len(keys), figsize=(4.6 * len(keys), 6.0), sharex="col", squeeze=False)
    style = {"jaxcelt": dict(color="k", lw=1.6), "Euler dt 0.002": dict(color="tab:red", lw=1.0),
             "Euler dt 0.0002": dict(color="tab:orange", lw=1.0, ls="--"), "RK4": dict(color="tab:blue", lw=1.0, ls=":")}  # fmt: skip
    for j, key in enumerate(keys):
        sc = res["scenes"][key]
        for r in sc["runs"]:
            st = next((v for k, v in style.items() if k in r["name"]), {})
            axes[0, j].plot(r["t"], r["omega_s"], label=r["name"], **st)
            axes[1, j].plot(r["t"], np.degrees(r["tilt"]), **st)
        axes[0, j].set_title(sc["description"], fontsize=9)
        axes[0, j].set_ylabel(r"$\omega_s = \omega\cdot n$ [rad/s]")
        axes[1, j].set_ylabel("tilt [deg]")
        axes[1, j].set_xlabel("t [s]")
        for a in axes[:, j]:
            a.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=7)
    fig.tight_layout()
    return fig


if __name__ == "__main__":
    main()
