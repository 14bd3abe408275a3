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

from jaxcelt.dataset import open_sweep
from jaxcelt.sweep import bifurcation

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


def test_refuses_other_sweep(tmp_path, paper_params):
    bifurcation(paper_params, VALUES, out=str(tmp_path), **KW)
    with pytest.raises(ValueError, match="different sweep"):
        bifurcation(paper_params, VALUES + 1, out=str(tmp_path), **KW)


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
