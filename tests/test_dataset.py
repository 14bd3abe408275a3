"""Datasets: self-describing attributes, chunk-by-chunk writing, resume gives identical results."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest
import xarray as xr
from _sweep_common import KW, VALUES

from jaxcelt.sweeps.api import bifurcation
from jaxcelt.sweeps.dataset import DamagedChunkWarning, open_sweep

VALUES8 = np.concatenate([VALUES, VALUES + 0.5])  # 2 chunks of the shared chunk shape (4 lanes)


def test_resume_identical(tmp_path, paper_params):
    full = tmp_path / "full"
    bifurcation(paper_params, VALUES8, out=str(full), **KW)
    ds_full = open_sweep(full)
    # attributes that make the file self-describing
    for key in (
        "params_json",
        "rtol",
        "atol",
        "solver",
        "versions_json",
        "switch_v_pi_sign",
        "switch_derivative_exact",
        "transient_periods",
    ):
        assert key in ds_full.attrs, key
    assert json.loads(ds_full.attrs["params_json"])["omega_pi"] == 17.0
    assert ds_full["section"].dims == ("omega_pi", "sample", "state")
    # xarray-loadable without jaxcelt
    with xr.open_dataset(full / "sweep.nc", engine="h5netcdf") as raw:
        assert raw.sizes["omega_pi"] == 8
    # "interrupted" run: only chunk 0 was on disk; the resumed run computes chunk 1
    part = tmp_path / "part"
    bifurcation(paper_params, VALUES8, out=str(part), **KW)
    os.remove(part / "chunks" / "chunk_00001.nc")
    os.remove(part / "sweep.nc")
    seen = []
    bifurcation(paper_params, VALUES8, out=str(part), on_chunk=lambda ci, r: seen.append(ci), **KW)
    assert seen == [1]  # chunk 0 was read back, not recomputed
    assert open_sweep(part).identical(ds_full)


def _damage(path, how):
    """Damage a chunk file as a torn write (first half of its bytes) or a bad copy (garbage)."""
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2] if how == "truncate" else os.urandom(len(data)))


def test_resume_recomputes_damaged_chunks(tmp_path, paper_params):
    # One chunk file truncated to half its bytes, another overwritten with random bytes, a third
    # from another sweep (a valid netCDF file whose fingerprint differs): the resume must warn
    # about each and recompute it, and end with the dataset of an uninterrupted run. Same machine,
    # same compiled program (the shared chunk shape) -> bitwise identical, as in the test above.
    values = np.concatenate([VALUES8, VALUES + 0.25])  # 3 chunks of 4 lanes
    full = tmp_path / "full"
    bifurcation(paper_params, values, out=str(full), **KW)
    part = tmp_path / "part"
    bifurcation(paper_params, values, out=str(part), **KW)
    other = tmp_path / "other"
    bifurcation(paper_params, values + 0.125, out=str(other), **KW)
    os.remove(part / "sweep.nc")
    chunks = part / "chunks"
    _damage(chunks / "chunk_00000.nc", "truncate")
    _damage(chunks / "chunk_00001.nc", "garbage")
    (chunks / "chunk_00002.nc").write_bytes((other / "chunks" / "chunk_00002.nc").read_bytes())
    seen = []
    with pytest.warns(DamagedChunkWarning) as rec:
        bifurcation(paper_params, values, out=str(part), on_chunk=lambda ci, r: seen.append(ci), **KW)
    msgs = [str(w.message) for w in rec if issubclass(w.category, DamagedChunkWarning)]
    assert len(msgs) == 3, msgs
    assert "chunk_00000.nc" in msgs[0] and "unreadable" in msgs[0]
    assert "chunk_00001.nc" in msgs[1] and "unreadable" in msgs[1]
    assert "chunk_00002.nc" in msgs[2] and "fingerprint" in msgs[2]
    assert seen == [0, 1, 2]
    assert open_sweep(part).identical(open_sweep(full))


def test_refuses_other_sweep(tmp_path, paper_params):
    bifurcation(paper_params, VALUES, out=str(tmp_path), **KW)
    with pytest.raises(ValueError, match="different sweep"):
        bifurcation(paper_params, VALUES + 1, out=str(tmp_path), **KW)


def _run_until_chunks(cmd, out, n_min=1):
    """Start the CLI, SIGKILL it once ``n_min`` chunk files exist; returns their paths."""
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    t0 = time.time()
    while len(list((out / "chunks").glob("chunk_*.nc")) if (out / "chunks").exists() else []) < n_min:
        assert time.time() - t0 < 300 and p.poll() is None
        time.sleep(0.01)  # once compiled, a chunk of this test takes milliseconds: look often
    p.send_signal(signal.SIGKILL)
    p.wait()
    return sorted((out / "chunks").glob("chunk_*.nc"))


@pytest.mark.slow
def test_killed_truncated_and_resumed(tmp_path):
    # An interrupted CLI sweep whose chunk file is then truncated (a torn write or a bad copy):
    # the rerun prints one warning line, recomputes that chunk and writes the dataset of an
    # uninterrupted run (same machine and program: identical).
    out = tmp_path / "run"
    # 16 chunks of one lane: the kill lands while chunks are still to be written (with 4 chunks of 2
    # lanes, the last three were once all written between two looks at the directory)
    cmd = [sys.executable, "-m", "jaxcelt", "bifurcation", "--omega", "12:19:16", "--transient", "3", "--sample", "4",
           "--lyapunov", "0", "--max-steps", "4000", "--chunk-size", "1", "--orbits", "", "--no-figures",
           "--out", str(out)]  # fmt: skip
    files = _run_until_chunks(cmd, out)
    assert not (out / "sweep.nc").exists() and len(files) < 16
    _damage(files[0], "truncate")
    rerun = subprocess.run(cmd, check=True, capture_output=True, text=True)
    warn = [s for s in rerun.stdout.splitlines() if "warning" in s]
    assert len(warn) == 1 and warn[0].startswith("jaxcelt bifurcation: warning: chunk file"), rerun.stdout[-2000:]
    assert files[0].name in warn[0]
    assert "Traceback" not in rerun.stderr
    ref = tmp_path / "ref"
    subprocess.run(cmd[:-1] + [str(ref)], check=True, capture_output=True)
    assert open_sweep(out).identical(open_sweep(ref))


@pytest.mark.slow
def test_killed_and_resumed(tmp_path):
    # A real kill (SIGKILL) of the CLI after its first chunk file appears, then a rerun.
    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "jaxcelt", "bifurcation", "--omega", "12:19:8", "--transient", "3", "--sample", "4",
           "--max-steps", "4000", "--chunk-size", "2", "--no-figures", "--out", str(out)]  # fmt: skip
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    t0 = time.time()
    while not list((out / "chunks").glob("chunk_*.nc")) if (out / "chunks").exists() else True:
        assert time.time() - t0 < 300 and p.poll() is None
        time.sleep(0.2)
    p.send_signal(signal.SIGKILL)
    p.wait()
    n_before = len(list((out / "chunks").glob("chunk_*.nc")))
    assert not (out / "sweep.nc").exists() and n_before < 4
    subprocess.run(cmd, check=True, capture_output=True)
    ref = tmp_path / "ref"
    subprocess.run(cmd[:-1] + [str(ref)], check=True, capture_output=True)
    a, b = open_sweep(out), open_sweep(ref)
    assert a.identical(b)
    print(textwrap.dedent(f"killed after {n_before} of 4 chunks; resumed dataset identical"))


def test_lane_fields_match_sweep_result():
    # dataset.py lists the lane variables itself (it does not import the sweep engine): the list
    # must be SweepResult's fields, in order
    import dataclasses

    from jaxcelt.sweeps.dataset import LANE_FIELDS
    from jaxcelt.sweeps.result import SweepResult

    assert LANE_FIELDS == tuple(f.name for f in dataclasses.fields(SweepResult) if f.name not in ("name", "values"))


def test_fingerprint_of_a_fixed_sweep_is_pinned(tmp_path):
    # an out/ directory written by earlier versions resumes only if the manifest's fingerprint is
    # computed as it was: this value is the one the released 0.1.0 layout (jaxcelt.sweep,
    # jaxcelt.dataset) wrote for this sweep; moving or renaming the sweep's classes must not change it
    import jaxcelt as jc
    from jaxcelt.sweeps.dataset import SweepWriter
    from jaxcelt.sweeps.options import SweepOptions

    cfg = SweepOptions(transient_periods=5, sample_periods=4, stop_on_invalid=True).config()
    p = jc.CeltParams.paper()
    vals = np.linspace(14, 16, 6)
    y0 = np.tile(np.asarray(jc.initial_state(p)), (6, 1))
    chunks = [np.array([0, 1]), np.array([2, 3]), np.array([4, 5])]
    w = SweepWriter(tmp_path, params=p, name="omega_pi", lane_values=vals, lane_y0=y0, n_starts=1, config=cfg, chunks=chunks)
    assert w.fingerprint == "88a0e7af8310975a9cbf4c6db259a293f22e4e13459d183a2036cc56b10d9ba2"
