"""What a stroboscopic chunk of lanes is run with: `SweepConfig` and the engines (`ENGINES`).

`SweepConfig` holds everything but the lanes' parameter values and starts: the section times
(transient and sampled periods), the Lyapunov window, the solver and its tolerances, the contact
law, the arithmetic. Its `SweepConfig.attrs` is what a sweep dataset records and fingerprints
(`jaxcelt.sweeps.dataset`). `check_engine` checks an engine name against a solver.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from jaxcelt.ensemble.kernel import kernel_supported
from jaxcelt.integrate.lyapunov import ERROR_CONTROLS, TANGENTS
from jaxcelt.integrate.solve import DEFAULT_SOLVER
from jaxcelt.physics.contact.registry import get_contact_law

__all__ = ["ENGINES", "SweepConfig", "check_engine"]

ENGINES = ("auto", "pool", "kernel")
"""how lanes are stepped: ``"pool"`` (`jaxcelt.ensemble.pool`, any solver, any device),
``"kernel"`` (`jaxcelt.ensemble.kernel`, explicit FSAL solvers; compiled for a GPU, interpreted
elsewhere) or ``"auto"``: the kernel on a GPU where the solver allows it, else the pool"""


@dataclasses.dataclass(frozen=True)
class SweepConfig:
    """Static settings of a sweep (everything but the parameter values and initial states)."""

    transient_periods: int = 200
    sample_periods: int = 100
    lyapunov_periods: int = 0
    """periods of tangent dynamics after the transient (0: no Lyapunov exponent)"""
    rtol: float = 1e-8
    atol: float = 1e-10
    max_steps: int = 1_000_000
    solver: Any = DEFAULT_SOLVER
    contact_law: Any = None
    t0: float = 0.0
    stop_on_invalid: bool = False
    """end a lane at the first accepted step whose end state is invalid (status 2, later samples inf)"""
    lyapunov_error_control: str = "state"
    """what the Lyapunov stage's step-size control measures (`jaxcelt.integrate.lyapunov.ERROR_CONTROLS`):
    ``"state"`` (default) or ``"all"`` (the state and the tangent vector)"""
    lyapunov_tangent: str = "difference"
    """how the Lyapunov stage forms the tangent vector's derivative (`jaxcelt.integrate.lyapunov.TANGENTS`):
    ``"difference"`` (default, a forward difference of the field) or ``"jvp"`` (forward-mode differentiation)"""
    stiffness: str = "off"
    """the lane kernel's stiffness switch (`jaxcelt.ensemble.stiff`): ``"auto"`` steps a lane with
    Rodas4P while its explicit steps are stability-limited (a stone sticking to the base), ``"off"``
    (default) keeps every step explicit. The pool's steps are the solver's alone"""
    field_dtype: str | None = None
    """mixed precision in the lane kernel: ``"float32"`` evaluates the field in float32 while the
    state, the stage sums and the error control stay in `dtype` (float64); None (default): the field
    in `dtype`. The pool has no mixed precision"""
    dtype: str = "float64"
    """"float64" (default) or "float32": the lanes' arithmetic (times stay float64 with an explicit FSAL
    solver, `jaxcelt.ensemble.float64_times`; the Lyapunov stage stays float64)"""

    def __post_init__(self):
        if self.stiffness not in ("auto", "off"):
            raise ValueError(f"'stiffness' must be 'auto' or 'off', got {self.stiffness!r}")
        if self.field_dtype not in (None, "float32", "float64"):
            raise ValueError(f"'field_dtype' must be None, 'float32' or 'float64', got {self.field_dtype!r}")
        if self.lyapunov_error_control not in ERROR_CONTROLS:
            raise ValueError(
                f"'lyapunov_error_control' must be one of {ERROR_CONTROLS}, got {self.lyapunov_error_control!r}"
            )
        if self.lyapunov_tangent not in TANGENTS:
            raise ValueError(f"'lyapunov_tangent' must be one of {TANGENTS}, got {self.lyapunov_tangent!r}")
        if self.dtype not in ("float64", "float32"):
            raise ValueError(f"'dtype' must be 'float64' or 'float32', got {self.dtype!r}")
        for name in ("transient_periods", "sample_periods", "lyapunov_periods", "max_steps"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | np.integer) or v < 0:
                raise ValueError(f"{name!r} must be a non-negative int, got {v!r}")
        if self.sample_periods < 1:
            raise ValueError(f"'sample_periods' must be >= 1, got {self.sample_periods}")
        if self.max_steps < 1:
            raise ValueError(f"'max_steps' must be >= 1, got {self.max_steps}")
        for name in ("rtol", "atol"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"{name!r} must be a positive finite number, got {v!r}")

    def attrs(self) -> dict[str, Any]:
        """Plain-python description (for dataset attributes)."""
        law = get_contact_law(self.contact_law)
        return dict(
            transient_periods=int(self.transient_periods),
            sample_periods=int(self.sample_periods),
            lyapunov_periods=int(self.lyapunov_periods),
            rtol=float(self.rtol),
            atol=float(self.atol),
            max_steps=int(self.max_steps),
            solver=type(self.solver).__name__,
            step_size_controller="PIDController + ClipStepSizeController(step_ts=section times)",
            contact_law=f"{type(law).__name__}(rolling_resistance={law.rolling_resistance})",
            t0=float(self.t0),
            stop_on_invalid=int(bool(self.stop_on_invalid)),
            dtype=str(self.dtype),
            **({} if self.stiffness == "off" else {"stiffness": str(self.stiffness)}),
            **({"lyapunov_error_control": str(self.lyapunov_error_control), "lyapunov_tangent": str(self.lyapunov_tangent)}
               if self.lyapunov_periods > 0 else {}),  # fmt: skip
            **({} if self.field_dtype is None else {"field_dtype": str(self.field_dtype)}),
        )


def check_engine(engine: str, solver: Any) -> None:
    """ValueError unless ``engine`` is one of `ENGINES` and can run ``solver``."""
    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {ENGINES}, got {engine!r}")
    if engine == "kernel" and not kernel_supported(solver):
        raise ValueError(f"engine='kernel' needs an explicit FSAL Runge-Kutta solver, got {type(solver).__name__}")
