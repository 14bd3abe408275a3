"""The `jaxcelt simulate` command: writes data + figure, reports bad input with exit code 2."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from jaxcelt.cli import main
from jaxcelt.integrate.io import load_trajectory

ROOT = Path(__file__).resolve().parents[1]


def test_simulate_writes_data_and_figure(tmp_path):
    rc = main(["simulate", "--omega-pi", "17", "--periods", "1", "--samples-per-period", "10", "--out", str(tmp_path)])
    assert rc == 0
    ts, ys, meta, extra = load_trajectory(tmp_path / "celt_w17.npz")
    assert ys.shape == (11, 13) and np.all(np.isfinite(ys))
    # the figure exists and is a PNG
    assert (tmp_path / "celt_w17.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    info = json.loads((tmp_path / "celt_w17.json").read_text())
    assert info["status"] == 0 and meta["params"]["omega_pi"] == 17.0
    # MODEL.md section 10: from rest at t = 2 pi/17, omega1 = -0.27424330708 (rtol 1e-8 run: 1e-6 tolerance)
    assert abs(ys[-1, 3] - (-0.27424330708)) < 1e-6


def test_simulate_rejects_bad_parameter(tmp_path, capsys):
    with pytest.raises(SystemExit) as e:
        main(["simulate", "--set", "m=-1", "--out", str(tmp_path)])
    assert e.value.code == 2
    assert "'m'" in capsys.readouterr().err
    assert not tmp_path.joinpath("celt_w17.npz").exists()


# Bad input in every command: one line "jaxcelt <command>: error: <message naming the parameter>"
# on stderr, exit status 2, nothing on stdout, no traceback; checked before any integration runs.
BAD_INPUT = [
    (["bifurcation", "--set", "mu=-1"], "'mu'"),
    (["bifurcation", "--set", "nonsense=3"], "nonsense"),
    (["bifurcation", "--set", "mu"], "--set"),
    (["bifurcation", "--omega", "14:15:abc"], "--omega"),
    (["bifurcation", "--omega", "14:15"], "--omega"),
    (["bifurcation", "--omega", "14:15:0"], "--omega"),
    (["bifurcation", "--transient", "-3"], "--transient"),
    (["bifurcation", "--sample", "0"], "--sample"),
    (["bifurcation", "--lyapunov", "x"], "--lyapunov"),
    (["bifurcation", "--rtol", "-1"], "--rtol"),
    (["bifurcation", "--omega0", "1,2"], "--omega0"),
    (["bifurcation", "--host-devices", "0"], "--host-devices"),
    (["bifurcation", "--host-processes", "0"], "--host-processes"),
    (["map", "--host-processes", "two"], "--host-processes"),
    (["bifurcation", "--engine", "gpu"], "--engine"),
    (["map", "--engine", "kernel", "--host-processes", "2"], "--engine"),
    (["bifurcation", "--param", "nonsense", "--values", "1,2"], "--param"),
    (["bifurcation", "--param", "mu"], "--values"),
    (["bifurcation", "--param", "mu", "--values", "0.1,-0.2"], "'mu'"),
    (["simulate", "--set", "m=-1"], "'m'"),
    (["simulate", "--periods", "0"], "--periods"),
    (["simulate", "--omega-pi", "nan"], "--omega-pi"),
    (["simulate", "--n0", "0,0"], "--n0"),
    (["ladder", "--scene", "nonsense"], "--scene"),
    (["ladder", "--laws", "pade,nonsense"], "--laws"),
    (["ladder", "--tol", "-1"], "--tol"),
    (["fit", "missing.npz", "--set", "mu=-1"], "'mu'"),
    (["fit", "missing.npz", "--max-iter", "0"], "--max-iter"),
    (["fit", "missing.npz"], "missing.npz"),
    (["orbits", "--continue", "20:10"], "--continue"),
    (["orbits", "--continue", "16:20"], "--continue"),
    (["orbits", "--param", "nonsense", "--continue", "1:2"], "--param"),
    (["orbits", "--set", "mu=-1"], "'mu'"),
    (["orbits", "--k", "0"], "--k"),
]


@pytest.mark.parametrize("argv,named", BAD_INPUT, ids=[" ".join(a) for a, _ in BAD_INPUT])
def test_bad_input_is_one_error_line(argv, named, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)  # outputs (if any were written) land here; "missing.npz" does not exist
    monkeypatch.delenv("JAXCELT_TRACEBACK", raising=False)
    monkeypatch.setenv("JAXCELT_CACHE_DIR", "off")
    with pytest.raises(SystemExit) as e:
        main(argv)
    assert e.value.code == 2
    out, err = capsys.readouterr()
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"jaxcelt {argv[0]}: error: "), lines[0]
    assert named in lines[0]
    assert "Traceback" not in err and out == ""
    assert not any(tmp_path.iterdir())  # rejected before anything was written


def test_bad_input_traceback_on_request(monkeypatch):
    # JAXCELT_TRACEBACK=1: the ValueError itself (for debugging), not the one-line report
    monkeypatch.setenv("JAXCELT_TRACEBACK", "1")
    monkeypatch.setenv("JAXCELT_CACHE_DIR", "off")
    with pytest.raises(ValueError, match="'mu'"):
        main(["bifurcation", "--set", "mu=-1"])


def test_bad_input_from_the_shell():
    # the installed entry point (python -m jaxcelt): exit status 2 and one stderr line
    cmd = [sys.executable, "-m", "jaxcelt", "bifurcation", "--set", "mu=-1"]
    r = subprocess.run(cmd, capture_output=True, text=True, env=dict(os.environ, JAXCELT_CACHE_DIR="off"))
    assert r.returncode == 2
    assert r.stderr.splitlines() == ["jaxcelt bifurcation: error: parameter 'mu' must be >= 0, got -1.0"]


def test_cli_engines_are_the_library_engines():
    from jaxcelt.commands.bifurcation import ENGINES
    from jaxcelt.ensemble import ENGINES as LIBRARY_ENGINES

    assert ENGINES == LIBRARY_ENGINES


def test_import_does_not_start_the_jax_backend():
    # `jax.config.update("jax_num_cpu_devices", n)` (the CLI's --host-devices) only works before
    # the backend starts; a module-level jnp array anywhere in jaxcelt would start it on import.
    code = (
        "import jax, jaxcelt, jaxcelt.cli, jaxcelt.commands.bifurcation, jaxcelt.plotting\n"
        "jax.config.update('jax_num_cpu_devices', 2)\n"
        "print(len(jax.devices('cpu')))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "2"


def test_compile_cache_is_written(tmp_path):
    # the CLI's persistent XLA cache: a run fills $JAXCELT_CACHE_DIR (a rerun then skips compiling).
    # Every program is stored (threshold 0 s): with the CLI's default of 1 s, whether this small
    # program is stored would depend on how fast the CPU compiles it.
    cache = tmp_path / "xla"
    env = dict(os.environ, JAXCELT_CACHE_DIR=str(cache), JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS="0")
    cmd = [sys.executable, "-m", "jaxcelt", "simulate", "--omega-pi", "17", "--periods", "1", "--out", str(tmp_path)]
    subprocess.run(cmd, env=env, check=True, capture_output=True)
    assert cache.is_dir() and any(cache.iterdir())


def test_bifurcation_solver_option(tmp_path):
    # --solver reaches the sweep: the dataset records it, and the lanes equal a Python-API sweep
    # with that solver (1e-10: the pool-vs-simulate agreement; the device count may differ, which
    # changes the compiled program and so the rounding, ~1e-11 over a few periods).
    from jaxcelt.sweeps.dataset import open_sweep

    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "jaxcelt", "bifurcation", "--omega", "14,17", "--transient", "1", "--sample", "2",
           "--lyapunov", "0", "--orbits", "", "--solver", "Dopri5", "--host-devices", "1", "--no-figures",
           "--out", str(out)]  # fmt: skip
    run = subprocess.run(cmd, check=True, capture_output=True, text=True, env=dict(os.environ, JAXCELT_CACHE_DIR="off"))
    ds = open_sweep(out)
    # the terminal summary: its regime ranges cover every lane, with the dataset's labels
    printed = _printed_ranges(run.stdout)
    assert sum(k for *_, k, _ in printed) == ds.sizes["omega_pi"] == 2
    for a, b, _, label in printed:
        lanes = ds.sel(omega_pi=slice(a, b))
        assert all(label.startswith(str(n)) for n in _labels(lanes))
    assert "sweep.nc" in run.stdout and "open_sweep(" in run.stdout
    assert json.loads(ds.attrs["config_json"])["solver"] == "Dopri5"
    assert json.loads((out / "summary.json").read_text())["solver"] == "Dopri5"
    import diffrax

    import jaxcelt as jc

    p = jc.CeltParams.paper()
    r = jc.bifurcation(p, [14.0, 17.0], transient_periods=1, sample_periods=2, solver=diffrax.Dopri5(),
                       stop_on_invalid=True)  # fmt: skip
    # the CLI (one host device) and this process (two) compile two programs: samples to rounding,
    # step counts within 1 % (measured: equal)
    np.testing.assert_allclose(ds["section"].values, r.samples, rtol=0, atol=1e-10)
    assert np.all(np.abs(ds["num_steps"].values - r.num_steps) <= np.maximum(2, 0.01 * r.num_steps))


def test_bifurcation_rejects_unknown_solver(capsys):
    with pytest.raises(SystemExit) as e:
        main(["bifurcation", "--solver", "RK45"])
    assert e.value.code == 2
    assert "invalid choice: 'RK45'" in capsys.readouterr().err


def _labels(ds):
    from jaxcelt.sweeps.regimes import regime_names

    return regime_names(ds["regime"].values, ds["period"].values)


def _printed_ranges(stdout: str) -> list[tuple[float, float, int, str]]:
    """(from, to, lanes, label) from the summary's lines ``  12.000 .. 13.000     2 lanes  period-1, bounded``."""
    import re

    pat = re.compile(r"^\s+([-\d.]+)(?: \.\. ([-\d.]+))?\s+(\d+) lanes?\s+(.+)$")
    out = []
    for line in stdout.splitlines():
        m = pat.match(line)
        if m:
            a = float(m[1])
            out.append((a, float(m[2]) if m[2] else a, int(m[3]), m[4].strip()))
    return out


def _fake_sweep():
    # a hand-made dataset: 2 invalid lanes (lift-off, n3 <= 0), 2 period-1 bounded, 1 chaotic unbounded
    import xarray as xr

    w = np.array([10.0, 11.0, 12.0, 13.0, 14.0])
    v = lambda a: ("omega_pi", np.array(a))
    return xr.Dataset(
        {
            "regime": v([1, 1, 2, 2, 4]),
            "period": v([0, 0, 1, 1, 0]),
            "global_motion": v([-1, -1, 0, 0, 1]),
            "valid": v(np.array([0, 0, 1, 1, 1], dtype=np.int8)),
            "first_invalid_kind": v([1, 2, 0, 0, 0]),
            "status": v([2, 2, 0, 0, 0]),
            "lyapunov": v([np.nan, np.nan, -0.5, -0.25, 1.5]),
        },
        coords={"omega_pi": w},
        attrs={
            "swept_parameter": "omega_pi",
            "config_json": json.dumps(
                {"transient_periods": 100, "sample_periods": 30, "solver": "Tsit5", "rtol": 1e-8}
            ),
        },
    )


def test_bifurcation_summary_text(tmp_path):
    from jaxcelt.commands.bifurcation import format_summary

    text = format_summary(_fake_sweep(), wall_seconds=12.34, out=tmp_path, files=["summary.json", "sweep.nc"])
    lines = text.splitlines()
    assert _printed_ranges(text) == [
        (10.0, 11.0, 2, "invalid"),
        (12.0, 13.0, 2, "period-1, bounded"),
        (14.0, 14.0, 1, "chaotic, unbounded"),
    ]
    assert lines[0].startswith("5 lanes, omega_pi 10 .. 14 rad/s; 100 transient + 30 sampled periods, Tsit5")
    assert "12.3 s" in lines[0]
    inv = next(x for x in lines if x.startswith("invalid lanes"))
    assert "2 of 5" in inv and "10..11" in inv and "1 lift-off" in inv and "1 contact off" in inv
    assert "largest Lyapunov exponent: -0.5 .. 1.5 1/s" in text
    assert "lanes per regime: invalid 2, period-1, bounded 2, chaotic, unbounded 1" in text
    assert f"open_sweep({str(tmp_path)!r})" in text and "summary.json, sweep.nc" in text
    assert len(lines) <= 12  # short: no JSON dump


def test_bifurcation_summary_caps_the_range_list(tmp_path):
    from jaxcelt.commands.bifurcation import format_summary

    ds = _fake_sweep()
    text = format_summary(ds, wall_seconds=1.0, out=tmp_path, files=[], max_ranges=2)
    assert len(_printed_ranges(text)) == 2 and "1 more ranges" in text


@pytest.mark.slow  # ~2 min: a transient, one Newton solve and a short branch, with compilation
def test_orbits_command_writes_orbit_branch_and_figures(tmp_path, monkeypatch):
    monkeypatch.setenv("JAXCELT_CACHE_DIR", "off")
    out = tmp_path / "orbits"
    code = main(["orbits", "--omega-pi", "15.6", "--continue", "15.5:15.7", "--max-points", "5", "--out", str(out)])
    assert code == 0
    r = json.loads((out / "orbits.json").read_text())
    assert r["orbit"]["status"] == "converged" and r["orbit"]["stable"]
    # the orbit reached from rest at psi0 = 157.5 deg is the one of docs/orbits/orbit_check.json
    ref = json.loads((ROOT / "docs/orbits/orbit_check.json").read_text())
    np.testing.assert_allclose(r["orbit"]["multipliers_abs"], ref["multipliers_abs"], atol=1e-6)
    vals = r["branch"]["values"]
    assert len(vals) == 5 and min(vals) < 15.6 < max(vals) and vals[r["branch"]["start"]] == 15.6
    assert (out / "branch.png").stat().st_size > 0 and (out / "multipliers.png").stat().st_size > 0
