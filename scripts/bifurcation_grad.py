"""Period-doubling point of the forced two-well Duffing oscillator and dF_PD/d(delta): IFT gradient vs
central finite differences -> docs/orbits/bifurcation_grad.json (timings indicative, load average recorded)."""

import json
import os
import pathlib
import time

import jax
import jax.numpy as jnp
import numpy as np

from jaxcelt.orbits.points import locate_period_doubling
from jaxcelt.orbits.shooting import stroboscopic_map
from jaxcelt.provenance import load_average, write_result
from jaxcelt.versions import versions

OMEGA, DELTA, H = 1.2, 0.3, 1e-4
T = 2 * np.pi / OMEGA


def duffing(t, y, a):
    F, delta = a
    return jnp.array([y[1], -delta * y[1] + y[0] - y[0] ** 3 + F * jnp.cos(OMEGA * t)])


def main() -> None:
    load0 = load_average()
    y = jnp.array([1.0, 0.0])
    for _ in range(60):
        y, _, _ = stroboscopic_map(duffing, y, (0.26, DELTA), period=T, rtol=1e-9, atol=1e-10)
    locate = lambda d: locate_period_doubling(  # noqa: E731
        duffing, y, 0.26, lambda F, dd: (F, dd), lambda a: T, d, rtol=1e-10, atol=1e-11
    )
    t = time.perf_counter()
    bp = locate(jnp.array(DELTA))
    t_first = time.perf_counter() - t
    t = time.perf_counter()
    bp = locate(jnp.array(DELTA))
    jax.block_until_ready(bp.value)
    t_second = time.perf_counter() - t
    t = time.perf_counter()
    g = float(jax.grad(lambda d: locate(d).value)(jnp.array(DELTA)))
    t_grad = time.perf_counter() - t
    fd = (float(locate(jnp.array(DELTA + H)).value) - float(locate(jnp.array(DELTA - H)).value)) / (2 * H)
    out = {
        "system": "x'' + delta x' - x + x^3 = F cos(1.2 t), delta = 0.3, period-1 orbit, right well",
        "F_pd": float(bp.value),
        "status": int(bp.status),
        "newton_steps": int(bp.newton_steps),
        "residual": float(bp.residual),
        "multipliers": [[float(m.real), float(m.imag)] for m in np.asarray(bp.multipliers)],
        "dF_pd_ddelta_grad": g,
        "dF_pd_ddelta_fd": fd,
        "fd_step": H,
        "relative_difference": abs(g - fd) / abs(fd),
        "seconds_locate_first_call": t_first,
        "seconds_locate_second_call": t_second,
        "seconds_grad_first_call": t_grad,
        "load_average": list(os.getloadavg()),
        "versions": versions(),
    }
    path = pathlib.Path(__file__).resolve().parents[1] / "docs/orbits/bifurcation_grad.json"
    write_result(path, out, load_at_start=load0, indent=2)
    print(json.dumps({k: v for k, v in out.items() if k != "versions"}, indent=2))


if __name__ == "__main__":
    main()
