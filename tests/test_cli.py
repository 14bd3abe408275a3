"""The `jaxcelt simulate` command: writes data + figure, reports bad input with exit code 2."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from jaxcelt.cli import main
from jaxcelt.io import load_trajectory


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
    # the CLI's persistent XLA cache: a run fills $JAXCELT_CACHE_DIR (a rerun then skips compiling)
    cache = tmp_path / "xla"
    env = dict(os.environ, JAXCELT_CACHE_DIR=str(cache))
    cmd = [sys.executable, "-m", "jaxcelt", "simulate", "--omega-pi", "17", "--periods", "1", "--out", str(tmp_path)]
    subprocess.run(cmd, env=env, check=True, capture_output=True)
    assert cache.is_dir() and any(cache.iterdir())


def test_bifurcation_solver_option(tmp_path):
    # --solver reaches the sweep: the dataset records it, and the lanes equal a Python-API sweep
    # with that solver (1e-10: the pool-vs-simulate agreement; the device count may differ, which
    # changes the compiled program and so the rounding, ~1e-11 over a few periods).
    from jaxcelt.dataset import open_sweep

    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "jaxcelt", "bifurcation", "--omega", "14,17", "--transient", "1", "--sample", "2",
           "--lyapunov", "0", "--orbits", "", "--solver", "Dopri5", "--host-devices", "1", "--no-figures",
           "--out", str(out)]  # fmt: skip
    subprocess.run(cmd, check=True, capture_output=True, env=dict(os.environ, JAXCELT_CACHE_DIR="off"))
    ds = open_sweep(out)
    assert json.loads(ds.attrs["config_json"])["solver"] == "Dopri5"
    assert json.loads((out / "summary.json").read_text())["solver"] == "Dopri5"
    import diffrax

    import jaxcelt as jc

    p = jc.CeltParams.paper()
    r = jc.bifurcation(p, [14.0, 17.0], transient_periods=1, sample_periods=2, solver=diffrax.Dopri5(),
                       stop_on_invalid=True)  # fmt: skip
    np.testing.assert_allclose(ds["section"].values, r.samples, rtol=0, atol=1e-10)
    np.testing.assert_array_equal(ds["num_steps"].values, r.num_steps)


def test_bifurcation_rejects_unknown_solver(capsys):
    with pytest.raises(SystemExit) as e:
        main(["bifurcation", "--solver", "RK45"])
    assert e.value.code == 2
    assert "invalid choice: 'RK45'" in capsys.readouterr().err
