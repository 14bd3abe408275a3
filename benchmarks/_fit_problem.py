"""The identification benchmarks' problem (``bench_fit``, ``bench_multistart``, ``fit_compile_parts``,
``fit_records_parallel``): two 1 s IMU records at 100 Hz of a stone with mu, k_r, b_Ts, m_Ts 30-50 %
off the paper's values, released tilted 10 deg spinning at +5 rad/s and tilted 6 deg at -3 rad/s.
jaxcelt is imported on first use, so a caller can configure JAX before."""

from __future__ import annotations

FREE = ("mu", "k_r", "b_Ts", "m_Ts")


def paper_and_true():
    """(the paper's parameters: every fit's start, the parameters the records are made with)."""
    import jaxcelt as jc

    paper = jc.CeltParams.paper()
    return paper, paper.replace(mu=0.2241 * 1.4, k_r=0.4345 * 0.6, b_Ts=0.5305 * 1.5, m_Ts=0.8161 * 1.35)


def release(p, tilt: float, spin: float, heading: float = 0.0):
    """A release state: tilted ``tilt`` deg about x2, spinning at ``spin`` rad/s, heading [rad]."""
    import numpy as np

    import jaxcelt as jc

    t = np.radians(tilt)
    return jc.initial_state(p, omega=(0.0, 0.0, spin), n=(np.sin(t), 0.0, np.cos(t)), psi=heading)


def records(noise: float = 0.0, kinds=("omega",)):
    """The two records (`jaxcelt.identify.records.MeasuredData`), noise as a fraction of each channel's RMS."""
    from jaxcelt.identify.records import generate_data

    _, true = paper_and_true()
    starts = [release(true, 10.0, 5.0), release(true, 6.0, -3.0)]
    return generate_data(true, starts, 1.0, rate=100, kinds=kinds, noise=noise)
