"""The `jaxcelt simulate` command: writes data + figure, reports bad input with exit code 2."""

import json

import numpy as np

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
    rc = main(["simulate", "--set", "m=-1", "--out", str(tmp_path)])
    assert rc == 2
    assert "'m'" in capsys.readouterr().out
