"""3-D animation of the stone (a semi-ellipsoid with a flat top) on the moving base."""

from __future__ import annotations

import numpy as np

from jaxcelt.physics.diagnostics import centre_position
from jaxcelt.physics.model import horizontal_frame
from jaxcelt.physics.params import CeltParams


def body_to_global(y, params: CeltParams):
    """(R, r_O): rotation body->global (rows E1, E2, n; MODEL.md section 4) and the position of O [m]."""
    y = np.asarray(y)
    frame = horizontal_frame(y[6:9], y[12])
    R = np.stack([np.asarray(frame.E1), np.asarray(frame.E2), y[6:9]])
    return R, np.asarray(centre_position(y, params))


def _surface(params: CeltParams, nu: int = 28, nv: int = 10):
    a1, a2, a3 = (float(params.a1), float(params.a2), float(params.a3))
    u = np.linspace(0, 2 * np.pi, nu)
    v = np.linspace(np.pi / 2, np.pi, nv)  # lower half: x3 <= 0 (the curved face; the top is flat)
    uu, vv = np.meshgrid(u, v)
    return np.stack([a1 * np.cos(uu) * np.sin(vv), a2 * np.sin(uu) * np.sin(vv), a3 * np.cos(vv)], -1)


def animate(ts, ys, params: CeltParams, *, stride: int = 1, interval_ms: int = 40, base_halfwidth: float = 0.15):
    """Return a `matplotlib.animation.FuncAnimation` of saved states ``ys`` (n, 13) at ``ts``.

    Display in a notebook with ``IPython.display.HTML(anim.to_jshtml())`` (no ffmpeg needed) or
    save a GIF with ``anim.save("celt.gif", writer="pillow")``. Lengths are drawn in mm.
    """
    import matplotlib.pyplot as plt
    from matplotlib import animation

    ts = np.asarray(ts)[::stride]
    ys = np.asarray(ys)[::stride]
    surf = _surface(params)
    q, w, s = float(params.q_pi), float(params.omega_pi), float(params.v_pi_sign)
    fig = plt.figure(figsize=(6, 5))
    ax = fig.add_subplot(projection="3d")
    centres = np.array([body_to_global(y, params)[1] for y in ys])
    cx, cy = centres[:, 0].mean() * 1e3, centres[:, 1].mean() * 1e3
    L = max(base_halfwidth * 1e3, np.abs(centres[:, :2] * 1e3 - [cx, cy]).max() + 120)

    def draw(i):
        ax.clear()
        R, rO = body_to_global(ys[i], params)
        P = (surf @ R.T + rO) * 1e3
        ax.plot_surface(P[..., 0], P[..., 1], P[..., 2], color="peru", edgecolor="saddlebrown", lw=0.2, alpha=0.9)
        d = s * q * (1 - np.cos(w * ts[i])) * 1e3  # base displacement along X1 (eq. 17 integrated)
        xs = np.array([cx - L, cx + L]) + d
        X, Y = np.meshgrid(xs, [cy - L, cy + L])
        ax.plot_surface(X, Y, np.zeros_like(X), color="lightsteelblue", alpha=0.35)
        ax.set(xlim=(cx - L, cx + L), ylim=(cy - L, cy + L), zlim=(-5, 60), xlabel="X1 [mm]", ylabel="X2 [mm]")
        ax.set_box_aspect((2 * L, 2 * L, 65))
        ax.set_zlabel("X3 [mm]")
        ax.set_title(f"t = {ts[i]:.2f} s")
        return ()

    return animation.FuncAnimation(fig, draw, frames=len(ts), interval=interval_ms, blit=False)
