"""The lane engine: many ODE solves side by side, each exactly as `jaxcelt.simulate` takes it.

* `lanes`: `LaneState` (one solve between two steps) and the per-lane outputs;
* `stepper`: one step of one lane -- `DiffraxStepper` (diffrax's own step) or
  `FusedERKStepper` (explicit FSAL Runge-Kutta, fused), behind `AbstractLaneStepper`;
* `pool`: `run_pool`, lanes through a fixed number of refilled batch slots in one jitted
  while loop, with `PoolStats`;
* `shard`: lanes over devices;
* `runners`: `AbstractLaneRunner`, the interface of whatever runs a chunk off this process's devices;
* `processes`: `HostProcesses`, lanes over single-device worker processes, one per CPU core;
* `kernel`: the lane kernel, every lane of a chunk stepped inside one GPU kernel, one thread
  per lane (Pallas, Triton backend), with the field re-expressed on lane blocks by `soa`; its
  stiffness switch in `stiff` (with the Rodas4P step of `rosenbrock`), and `kernel_ode`'s
  `solve_lanes`, the kernel for any ODE (final states);
* `config`: `SweepConfig`, the settings of a stroboscopic chunk, and the engines (`ENGINES`);
* `stroboscopic`: `run_lanes`, one chunk of lanes sampled at the forcing's section times,
  sharded over devices, through the pool or the kernel (`ENGINES`), with the optional Lyapunov
  stage.
* `lane_programs`: the jitted programs `run_lanes` runs a chunk through: the pool's (start,
  full-width phase, drain, outputs; `prepare_pool`) and what they share with the kernel's.

The user-facing sweeps (`jaxcelt.sweeps`: `bifurcation`, `parameter_map`, ...) are built on it; the engine
imports nothing of them (nor of `jaxcelt.orbits` or `jaxcelt.identify`).
The diffrax internals it mirrors live in `jaxcelt._diffrax_adapter`.
"""

from jaxcelt.ensemble.config import ENGINES as ENGINES
from jaxcelt.ensemble.config import SweepConfig as SweepConfig
from jaxcelt.ensemble.config import check_engine as check_engine
from jaxcelt.ensemble.kernel import BLOCK as BLOCK
from jaxcelt.ensemble.kernel import kernel_supported as kernel_supported
from jaxcelt.ensemble.kernel_ode import solve_lanes as solve_lanes
from jaxcelt.ensemble.lanes import LaneMonitor as LaneMonitor
from jaxcelt.ensemble.lanes import LaneOutputs as LaneOutputs
from jaxcelt.ensemble.lanes import LaneState as LaneState
from jaxcelt.ensemble.lanes import lane_status as lane_status
from jaxcelt.ensemble.pool import DEFAULT_WIDTH as DEFAULT_WIDTH
from jaxcelt.ensemble.pool import MIN_DRAIN_WIDTH as MIN_DRAIN_WIDTH
from jaxcelt.ensemble.pool import PILOT_FRACTION as PILOT_FRACTION
from jaxcelt.ensemble.pool import PoolStats as PoolStats
from jaxcelt.ensemble.pool import lane_outputs as lane_outputs
from jaxcelt.ensemble.pool import run_pool as run_pool
from jaxcelt.ensemble.pool import split_lane_args as split_lane_args
from jaxcelt.ensemble.pool import start_lanes as start_lanes
from jaxcelt.ensemble.processes import HostProcesses as HostProcesses
from jaxcelt.ensemble.runners import AbstractLaneRunner as AbstractLaneRunner
from jaxcelt.ensemble.shard import device_mesh as device_mesh
from jaxcelt.ensemble.shard import pad_lanes as pad_lanes
from jaxcelt.ensemble.shard import shard_lanes as shard_lanes
from jaxcelt.ensemble.soa import blockwise as blockwise
from jaxcelt.ensemble.stepper import AbstractLaneStepper as AbstractLaneStepper
from jaxcelt.ensemble.stepper import DiffraxStepper as DiffraxStepper
from jaxcelt.ensemble.stepper import DiffraxStepState as DiffraxStepState
from jaxcelt.ensemble.stepper import FusedERKStepper as FusedERKStepper
from jaxcelt.ensemble.stepper import FusedStepState as FusedStepState
from jaxcelt.ensemble.stepper import erk_tableau as erk_tableau
from jaxcelt.ensemble.stepper import kernel_boundary as kernel_boundary
from jaxcelt.ensemble.stepper import make_stepper as make_stepper
from jaxcelt.ensemble.stroboscopic import LYAPUNOV_GROUP_WIDTH as LYAPUNOV_GROUP_WIDTH
from jaxcelt.ensemble.stroboscopic import lanes_params as lanes_params
from jaxcelt.ensemble.stroboscopic import run_lanes as run_lanes
from jaxcelt.ensemble.stroboscopic import run_lanes_with_stats as run_lanes_with_stats  # deprecated
