"""`jaxcelt map --curves FILE` and the library drawing (`jaxcelt.plotting.map`): bifurcation curves over a map.

* `map_curve_lines` picks the curves in the map's two parameters from a curves result file (the committed
  docs/orbits/fold_curves.json: its four (omega_pi, q_pi) pieces and no others for that pair; its (omega_pi, mu)
  curve for that pair), marks the neutral-saddle stretch of a Neimark-Sacker curve (|kappa| > 1) and raises a
  ValueError naming ``curves`` where none matches.
* `map_figure(..., curves=...)` draws them on both panels (a synthetic 3 x 2 map; the line data are checked).
* CLI: a missing, non-JSON or non-matching ``--curves`` file is one stderr line naming ``--curves``, exit 2, before
  any work; a smoke-size map (2 x 2 lanes, 1 + 2 periods) with the committed fold curves writes its figure.
"""

import json
from pathlib import Path

import matplotlib
import numpy as np
import pytest
import xarray as xr

from jaxcelt.cli import main
from jaxcelt.plotting.map import map_curve_lines, map_figure

matplotlib.use("Agg")
ROOT = Path(__file__).resolve().parents[1]
FOLDS = ROOT / "docs/orbits/fold_curves.json"


def _ns_curve():
    return {
        "kind": "neimark-sacker",
        "omega_pi": [15.0, 16.0, 17.0, 18.0],
        "q_pi": [0.03, 0.035, 0.04, 0.045],
        "kappa": [1.2, 0.9, 0.5, -0.5],
        "points": [{"kind": "1:1 resonance", "omega_pi": 15.5, "q_pi": 0.0325}],
    }


def test_curve_lines_from_the_committed_fold_curves_and_a_ns_curve():
    data = json.loads(FOLDS.read_text())
    lines = map_curve_lines(data, "omega_pi", "q_pi")
    assert sorted(ln["key"] for ln in lines) == ["q_pi", "q_pi_upper", "q_pi_upper2"]
    assert all(ln["kind"] == "fold" and ln["ns"].all() for ln in lines)
    assert [ln["key"] for ln in map_curve_lines(data, "omega_pi", "mu")] == ["mu"]
    (ns,) = map_curve_lines({"curves": {"a": {"curve": _ns_curve()}}}, "omega_pi", "q_pi")
    assert ns["ns"].tolist() == [False, True, True, True] and ns["points"] == [("1:1 resonance", 15.5, 0.0325)]
    with pytest.raises(ValueError, match="curves: no curve in the map's parameters \\(omega_pi, b\\)"):
        map_curve_lines(data, "omega_pi", "b")
    with pytest.raises(ValueError, match="curves"):
        map_curve_lines([1, 2], "omega_pi", "q_pi")


def test_map_figure_draws_curves_on_both_panels():
    x, y = np.array([14.0, 16.0, 18.0]), np.array([0.03, 0.05])
    shape = (3, 2)
    ds = xr.Dataset(
        {
            "regime": (("omega_pi", "q_pi"), np.full(shape, 2)),
            "period": (("omega_pi", "q_pi"), np.ones(shape, int)),
            "global_motion": (("omega_pi", "q_pi"), np.zeros(shape, int)),
            "lyapunov": (("omega_pi", "q_pi"), np.linspace(-0.5, 0.5, 6).reshape(shape)),
        },
        coords={"omega_pi": x, "q_pi": y},
        attrs={"x_parameter": "omega_pi", "y_parameter": "q_pi"},
    )
    fig = map_figure(ds, curves=_ns_curve())
    for ax in fig.axes[:2]:
        drawn = [ln for ln in ax.get_lines() if len(ln.get_xdata()) == 4]
        assert len(drawn) == 2  # the Neimark-Sacker stretch (thick) and the whole curve (thin, dotted)
        np.testing.assert_array_equal(drawn[0].get_xdata(), [15.0, 16.0, 17.0, 18.0])
        assert np.isnan(drawn[0].get_ydata()[0]) and drawn[0].get_ydata()[1] == 0.035
    assert fig.axes[1].get_legend() is not None
    with pytest.raises(ValueError, match="curves"):
        map_figure(ds, curves={"curves": {}})


@pytest.mark.parametrize(
    "content, named",
    [(None, "cannot read"), ("{not json", "is not JSON"), ('{"kind": "fold", "mu": [1], "q_pi": [1]}', "no curve")],
)
def test_bad_curves_file_is_one_error_line(content, named, tmp_path, capsys):
    f = tmp_path / "c.json"
    if content is not None:
        f.write_text(content)
    with pytest.raises(SystemExit) as e:
        main(["map", "--x", "omega_pi=14,17", "--y", "q_pi=0.04,0.05", "--curves", str(f), "--out", str(tmp_path)])
    assert e.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("jaxcelt map: error: argument --curves") and named in err[0], err
    assert not (tmp_path / "summary.json").exists()


def test_smoke_map_with_curves(tmp_path):
    out = tmp_path / "m"
    rc = main(["map", "--x", "omega_pi=14,17", "--y", "q_pi=0.04,0.05", "--transient", "1", "--sample", "2",
               "--lyapunov", "0", "--host-devices", "1", "--curves", str(FOLDS), "--out", str(out)])  # fmt: skip
    assert rc == 0
    assert (out / "map.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert json.loads((out / "summary.json").read_text())["curves"] == str(FOLDS)
