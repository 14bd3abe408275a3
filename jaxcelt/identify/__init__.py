"""Identification: fitting the model's parameters to measured trajectories.

Entry points:

* `jaxcelt.identify.api`: `fit` (one fit; its options are one `FitOptions`, `jaxcelt.identify.options`).
* `jaxcelt.identify.strategies`: `fit_staged` (growing spans), `multistart` with `random_guesses`,
  `profile_likelihood`.
* `jaxcelt.identify.records`: measured records (`Trajectory`, `MeasuredData`), `generate_data`, the file formats
  (`save_data`, `load_data`, `from_arrays`, `save_csv`, `load_csv`).
* `jaxcelt.identify.result`: `FitResult` and `predict`.

The machinery under them: `jaxcelt.identify.observe` (the sensor model: `observe`, `OBSERVABLES`, `specific_force`,
`rotation_matrix`), `jaxcelt.identify.transforms` (parameter transforms), `jaxcelt.identify.problem` (the problem
and its residuals), `jaxcelt.identify.program` (the compiled evaluation program), `jaxcelt.identify.optimisers`
(LM, Gauss-Newton, Adam, L-BFGS and their loops) and `jaxcelt.identify.chaos` (Lyapunov growth and the gradient
against the window length).
"""

from jaxcelt.identify.api import fit
from jaxcelt.identify.chaos import finite_time_lyapunov, gradient_norm_vs_window
from jaxcelt.identify.observe import OBSERVABLES, SENSOR_KINDS, observe, rotation_matrix, specific_force
from jaxcelt.identify.optimisers import DampedGaussNewton
from jaxcelt.identify.options import LSQ_OPTIMISERS, OPTIMISERS, STEPS_PER_SECOND, FitOptions
from jaxcelt.identify.problem import STATE_SCALE, TIME_OFFSET_SCALE
from jaxcelt.identify.records import (
    CSV_COLUMNS,
    MeasuredData,
    Trajectory,
    from_arrays,
    generate_data,
    load_csv,
    load_data,
    save_csv,
    save_data,
)
from jaxcelt.identify.result import FitResult, predict
from jaxcelt.identify.strategies import fit_staged, multistart, profile_likelihood, random_guesses
from jaxcelt.identify.transforms import DEFAULT_TRANSFORMS, Affine, Bounded, Positive

__all__ = [
    "fit",
    "FitOptions",
    "FitResult",
    "predict",
    "fit_staged",
    "multistart",
    "random_guesses",
    "profile_likelihood",
    "Trajectory",
    "MeasuredData",
    "generate_data",
    "save_data",
    "load_data",
    "from_arrays",
    "save_csv",
    "load_csv",
    "CSV_COLUMNS",
    "OBSERVABLES",
    "SENSOR_KINDS",
    "observe",
    "specific_force",
    "rotation_matrix",
    "Positive",
    "Bounded",
    "Affine",
    "DEFAULT_TRANSFORMS",
    "OPTIMISERS",
    "LSQ_OPTIMISERS",
    "STEPS_PER_SECOND",
    "STATE_SCALE",
    "TIME_OFFSET_SCALE",
    "DampedGaussNewton",
    "finite_time_lyapunov",
    "gradient_norm_vs_window",
]
