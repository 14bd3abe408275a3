"""Studies of the model itself rather than of the stone's dynamics.

* `ladder` -- which contact law a scene needs: a scene is simulated with each law of a ladder (integral law down
  to rolling without slip) and the cheapest law that keeps the scene's quantities within a tolerance is
  recommended (`run_ladder`, `recommend`).
* `benchmarking` -- speed against accuracy: named test problems (`BenchmarkScene`), the error measure, timed
  solver runs, right-hand-side counts. The scripts in ``benchmarks/`` build on it.
"""

from jaxcelt.studies.ladder import Scene, hertz_params, recommend, run_ladder

__all__ = ["Scene", "hertz_params", "recommend", "run_ladder"]
