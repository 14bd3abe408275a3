"""Sweeps: many lanes of the engine over parameter values and starts, sampled on the stroboscopic section.

Entry points:

* `api`: `sweep` (one `jaxcelt.CeltParams` field over values, one or several starts -> `SweepResult`),
  `bifurcation` (over omega_pi), `parameter_map` (a grid of two fields -> `xarray.Dataset`),
  `sweep_lanes` (any batch of lanes -> `xarray.Dataset`);
* `following`: `follow_attractor`, each value started from the previous value's final state
  (hysteresis; formerly ``continuation``);
* `census`: `attractors`, the distinct attractors reached from many starts at one parameter value;
* `continuation`: `continue_attractors`, global continuation of the attractors over one parameter (seeds from
  the previous value, matching, basin fractions; resumable), on the model-agnostic `continuation_core`
  (`continue_section_attractors`, any forced ODE via `continuation_ode.forced_ode_model`);
* `atlas`: `atlas`, everything over omega_pi at once (brute force, continuation, periodic branches, exponents);
* `dense`: `dense_trajectory`, many states per period at one value, for phase plots.

Their parts:

* `options`: `SweepOptions`, the one options object of every sweep (sampling, solver, execution);
* `result`: `SweepResult` and the lane schema (`LANE_FIELDS`, `LANE_DIMS`);
* `driver`: `run_batch` -- chunks, resumable writing, several processes (`jax.distributed`);
* `dataset`: the xarray/netCDF files (``out/sweep.nc``, chunk files, manifest) and their resume;
* `continuation_options` (`ContinuationOptions`), `continuation_match` (lane kinds, grouping, matching),
  `continuation_store` (one resumable file per value), `continuation_result` (the continuation's dataset);
* `regimes`: regime labels (period-k, quasi-periodic, chaotic, ...) and regime ranges along a sweep.

The lanes themselves run on `jaxcelt.ensemble`; periodic orbits and their continuation along a
branch are `jaxcelt.orbits`.
"""

from jaxcelt.sweeps.api import bifurcation as bifurcation
from jaxcelt.sweeps.api import parameter_map as parameter_map
from jaxcelt.sweeps.api import sweep as sweep
from jaxcelt.sweeps.api import sweep_lanes as sweep_lanes
from jaxcelt.sweeps.atlas import AtlasOptions as AtlasOptions
from jaxcelt.sweeps.atlas import AtlasResult as AtlasResult
from jaxcelt.sweeps.atlas import atlas as atlas
from jaxcelt.sweeps.census import Attractor as Attractor
from jaxcelt.sweeps.census import AttractorCensus as AttractorCensus
from jaxcelt.sweeps.census import AttractorStarts as AttractorStarts
from jaxcelt.sweeps.census import attractor_starts as attractor_starts
from jaxcelt.sweeps.census import attractors as attractors
from jaxcelt.sweeps.census import refine_attractor as refine_attractor
from jaxcelt.sweeps.continuation import continue_attractors as continue_attractors
from jaxcelt.sweeps.continuation_core import continue_section_attractors as continue_section_attractors
from jaxcelt.sweeps.continuation_options import ContinuationOptions as ContinuationOptions
from jaxcelt.sweeps.dense import dense_trajectory as dense_trajectory
from jaxcelt.sweeps.dense import prepare_dense_trajectory as prepare_dense_trajectory
from jaxcelt.sweeps.driver import run_batch as run_batch
from jaxcelt.sweeps.following import follow_attractor as follow_attractor
from jaxcelt.sweeps.options import SweepOptions as SweepOptions
from jaxcelt.sweeps.regimes import GLOBAL_MOTION as GLOBAL_MOTION
from jaxcelt.sweeps.regimes import REGIMES as REGIMES
from jaxcelt.sweeps.regimes import classify as classify
from jaxcelt.sweeps.regimes import detect_period as detect_period
from jaxcelt.sweeps.regimes import regime_names as regime_names
from jaxcelt.sweeps.regimes import regime_ranges as regime_ranges
from jaxcelt.sweeps.regimes import regime_runs as regime_runs
from jaxcelt.sweeps.result import LANE_DIMS as LANE_DIMS
from jaxcelt.sweeps.result import LANE_FIELDS as LANE_FIELDS
from jaxcelt.sweeps.result import SweepResult as SweepResult

_DATASET = ("open_sweep", "SweepWriter", "DamagedChunkWarning", "to_dataset", "to_map_dataset", "SWEEP_FILE")


def __getattr__(name: str):
    """The `dataset` names, imported on first use (xarray is not imported with the package)."""
    if name in _DATASET:
        from jaxcelt.sweeps import dataset

        return getattr(dataset, name)
    raise AttributeError(f"module 'jaxcelt.sweeps' has no attribute {name!r}")
