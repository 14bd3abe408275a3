"""The module paths from before the topic packages keep working for one release (`jaxcelt._moved`).

The names below are the public names (``__all__``) each old module had; every one must still be reachable through
the old path, with a `DeprecationWarning` that names the new place, and be the same object as at the new place.
"""

import importlib
import subprocess
import sys
import warnings

import pytest

import jaxcelt as jc

# ``__all__`` of each module of the flat layout, listed when the modules moved.
OLD_NAMES = {
    'params': ['CeltParams', 'PARAM_NAMES', 'inertia_tensor'],
    'state': ['MANIFOLD_TOL', 'check_state', 'constraint_residual', 'initial_state'],
    'model': ['Frame', 'Geometry', 'Kinematics', 'STATE_NAMES', 'contact_geometry', 'contact_loads', 'field_time', 'horizontal_frame', 'kinematics', 'normal_force', 'normal_force_parts', 'patch_frame', 'split_state', 'vector_field', 'vector_field_and_normal'],
    'diagnostics': ['Diagnostics', 'centre_position', 'diagnostics', 'energy', 'tilt'],
    'contact': ['AbstractContactLaw', 'CONTACT_LAWS', 'ContactKinematics', 'ContactLoads', 'Coulomb', 'CoulombSpin', 'GeneralisedPade', 'Pade', 'get_contact_law', 'law_name', 'pade_friction', 'safe_abs_pow'],
    'integral_law': ['AbstractPressureProfile', 'CustomProfile', 'HERTZ_S', 'HertzProfile', 'IntegralLaw', 'UniformProfile', 'patch_integrals', 'profile_moments'],
    'elliptic': ['contact_integrals', 'ellipke'],
    'calibrate': ['Calibration', 'SlipSamples', 'approximant_values', 'calibrate', 'error_map', 'integral_reference', 'slip_samples'],
    'solve': ['DEFAULT_SOLVER', 'INVALID_KINDS', 'MonitoredSolver', 'STATUS', 'Solution', 'Validity', 'simulate'],
    'noslip': ['NOSLIP_STATE_NAMES', 'NoSlipForce', 'noslip_contact_force', 'noslip_full_state', 'noslip_reduce', 'noslip_vector_field', 'simulate_noslip'],
    'lyapunov': ['CELT_NORM_MASK', 'LyapunovResult', 'STDERR_BLOCKS', 'celt_lyapunov', 'celt_tangent_projection', 'exponent_stderr', 'largest_lyapunov'],
    'io': ['load_trajectory', 'save_trajectory'],
    'sweep': ['SweepConfig', 'SweepResult', 'bifurcation', 'continuation', 'lanes_params', 'orbit', 'parameter_map', 'parse_range', 'prepare_orbit', 'run_lanes', 'run_lanes_with_stats', 'sweep', 'sweep_lanes'],
    'dataset': ['DamagedChunkWarning', 'SWEEP_FILE', 'SweepWriter', 'open_sweep', 'to_dataset', 'to_map_dataset'],
    'regimes': ['GLOBAL_MOTION', 'REGIMES', 'classify', 'detect_period', 'regime_names'],
    'attractors': ['Attractor', 'AttractorCensus', 'AttractorStarts', 'attractor_starts', 'attractors', 'refine_attractor', 'same_cycle'],
    'periodic': ['ORBIT_STATUS', 'PeriodicOrbit', 'find_periodic_orbit', 'sort_multipliers', 'stroboscopic_map', 'variational_map'],
    'orbit_continuation': ['ArclengthBranch', 'BIFURCATION_KINDS', 'Bifurcation', 'OrbitBranch', 'branch_to_dict', 'continue_periodic_orbit', 'continue_pseudo_arclength', 'switch_at_period_doubling'],
    'bifurcation_point': ['BIFURCATION_POINT_KINDS', 'BifurcationPoint', 'locate_bifurcation', 'locate_fold', 'locate_period_doubling'],
    'celt_orbit': ['CeltOrbit', 'ORBIT_STATUS', 'celt_chart', 'celt_embed', 'continue_orbit', 'locate_orbit_bifurcation', 'periodic_orbit'],
    'data': ['CSV_COLUMNS', 'MeasuredData', 'OBSERVABLES', 'SENSOR_KINDS', 'Trajectory', 'from_arrays', 'generate_data', 'load_csv', 'load_data', 'observe', 'rotation_matrix', 'save_csv', 'save_data', 'specific_force'],
    'fit': ['Affine', 'Bounded', 'DEFAULT_TRANSFORMS', 'DampedGaussNewton', 'FitResult', 'OPTIMISERS', 'Positive', 'STATE_SCALE', 'finite_time_lyapunov', 'fit', 'fit_staged', 'gradient_norm_vs_window', 'multistart', 'predict', 'profile_likelihood', 'project_state', 'random_guesses'],
    'ladder': ['HERTZ_CALIBRATED', 'OBSERVABLES', 'Rung', 'RungResult', 'Scene', 'builtin_scenes', 'default_ladder', 'hertz_params', 'law_name', 'needed_state', 'recommend', 'results_table', 'run_ladder'],
    'benchmarking': ['CountingLaw', 'FixedStep', 'RK4', 'SCENES', 'SOLVERS', 'Scene', 'count_rhs_evals', 'device_string', 'make_scene', 'make_solver', 'run_diffrax', 'state_error', 'time_call'],
}


@pytest.mark.parametrize("old", sorted(OLD_NAMES))
def test_every_old_name_is_reachable_and_warns(old):
    module = importlib.import_module(f"jaxcelt.{old}")
    for name in OLD_NAMES[old]:
        with pytest.warns(DeprecationWarning, match=rf"jaxcelt\.{old} is deprecated.*use jaxcelt\."):
            obj = getattr(module, name)
        assert obj is not None, (old, name)


def test_old_paths_give_the_new_objects():
    from jaxcelt.identify.records import load_csv
    from jaxcelt.sweeps.dataset import open_sweep
    from jaxcelt.sweeps.regimes import classify

    with pytest.warns(DeprecationWarning, match="jaxcelt.sweeps.dataset.open_sweep"):
        from jaxcelt.dataset import open_sweep as old_open
    with pytest.warns(DeprecationWarning, match="jaxcelt.sweeps.regimes.classify"):
        from jaxcelt.regimes import classify as old_classify
    with pytest.warns(DeprecationWarning, match="jaxcelt.identify.records.load_csv"):
        from jaxcelt.data import load_csv as old_load_csv
    with pytest.warns(DeprecationWarning, match="jaxcelt.identify.result.FitResult"):
        from jaxcelt.fit import FitResult
    with pytest.warns(DeprecationWarning, match="jaxcelt.sweeps.api.sweep"):
        from jaxcelt.sweep import sweep
    assert (old_open, old_classify, old_load_csv, FitResult) == (open_sweep, classify, load_csv, jc.FitResult)
    assert sweep is jc.sweeps.sweep


def test_functions_named_like_old_modules_stay_functions():
    # jaxcelt.fit, jaxcelt.attractors and jaxcelt.diagnostics are functions; importing the old module path of the
    # same name must not replace them (a fresh interpreter, so no earlier import hides the effect)
    code = (
        "import jaxcelt, jaxcelt.fit, jaxcelt.attractors, jaxcelt.diagnostics\n"
        "from jaxcelt.fit import fit_staged\n"
        "assert callable(jaxcelt.fit) and callable(jaxcelt.attractors) and callable(jaxcelt.diagnostics)\n"
        "assert jaxcelt.fit.__module__ == 'jaxcelt.identify.api'\n"
    )
    subprocess.run([sys.executable, "-W", "ignore::DeprecationWarning", "-c", code], check=True)


def test_public_names_do_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for name in jc.__all__:
            getattr(jc, name)


def test_unknown_name_on_an_old_path_names_the_new_modules():
    import jaxcelt.sweep as old

    with pytest.raises(AttributeError, match="moved to jaxcelt.sweeps"):
        old.no_such_name  # noqa: B018
