"""`jaxcelt bifurcation --atlas`: the main job with the atlas over omega_pi and phase plots started on attractors."""

from __future__ import annotations

import json

import pytest

from jaxcelt.cli import main


@pytest.mark.parametrize("argv", [["--param", "mu", "--values", "0.2,0.3"], ["--set", "mu=0.2"]])
def test_atlas_needs_omega_at_the_papers_parameters(argv, tmp_path, capsys):
    with pytest.raises(SystemExit) as e:
        main(["bifurcation", "--atlas", "--out", str(tmp_path), *argv])
    assert e.value.code == 2
    assert "--atlas" in capsys.readouterr().err
    assert not (tmp_path / "summary.json").exists()


@pytest.mark.slow
def test_main_job_with_the_atlas(tmp_path):
    # a short main job with the atlas at its default size (minutes on 2 cores): the atlas files, and phase plots
    # that start on the attractor with the largest basin at 15.6 rad/s (the mirror period-1 pair there)
    rc = main(["bifurcation", "--atlas", "--out", str(tmp_path), "--omega", "14:19:6", "--transient", "40",
               "--sample", "10", "--lyapunov", "0", "--orbits", "15.6", "--orbit-periods", "5"])  # fmt: skip
    assert rc == 0
    for f in ("atlas/atlas.png", "atlas/atlas.json", "atlas/atlas.nc", "bifurcation_regime.png", "orbit_omega15.6.png"):
        assert (tmp_path / f).exists(), f
    summary = json.loads((tmp_path / "summary.json").read_text())
    start = summary["atlas"]["phase_plot_starts"]["15.6"]
    assert "period-1" in start, start
