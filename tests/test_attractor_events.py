"""The explanations of `scripts/attractor_events.py` on constructed changes, and the committed result.

The rules are simple enough to check by hand: a periodic attractor that appears where the branch has a fold
inside the interval is born at the fold; a set whose long-run lanes all tip over is a chaotic transient; a set
that survives its long run and whose seeds all tip over at the next value is lost in a boundary crisis; a basin
of fraction f is missed by N starts with chance (1 - f)^N (exact binomial arithmetic).
"""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location("attractor_events", ROOT / "scripts" / "attractor_events.py")
E = importlib.util.module_from_spec(spec)
spec.loader.exec_module(E)

BIF = [dict(kind="fold", value=14.88, branch="a"), dict(kind="Neimark-Sacker", value=17.75, branch="a")]
PRESENT = {14.5: {4}, 15.0: {5, 7}, 17.5: {5}, 18.0: {5}}


def _set(kind, fraction=0.2, orbit_mu=None, period=0):
    return dict(kind=kind, period=period, fraction=fraction, orbit_mu=orbit_mu)


def _run(lanes, tipped):
    return dict(lanes=lanes, tipped=tipped)


@pytest.mark.parametrize(
    "ev, cls",
    [
        (dict(change="appears", after=_set("periodic", period=1), **{"from": 14.5, "to": 15.0}), "fold"),
        (dict(change="appears", after=_set("periodic", 0.02, period=1), **{"from": 15.0, "to": 15.5}), "sampling"),
        (dict(change="relabelled", before=_set("converging", orbit_mu=0.998), after=_set("uncertain", orbit_mu=1.001),
              **{"from": 17.5, "to": 18.0}), "Neimark-Sacker"),
        (dict(change="relabelled", before=_set("periodic", orbit_mu=0.95), after=_set("converging", orbit_mu=0.98),
              **{"from": 16.0, "to": 16.5}), "label only"),
        (dict(change="vanishes", before=_set("chaotic"), long_before=_run(9, 9), seeds_next={"-1": 4},
              **{"from": 19.0, "to": 19.5}), "chaotic transient"),
        (dict(change="vanishes", before=_set("chaotic"), long_before=_run(4, 0), seeds_next={"-1": 4},
              **{"from": 11.5, "to": 12.0}), "boundary crisis"),
        (dict(change="vanishes", before=_set("chaotic"), long_before=_run(4, 0), seeds_next={"7": 4},
              **{"from": 14.5, "to": 15.0}), "merged"),
        (dict(change="appears", after=_set("uncertain"), from_seeds=[4], **{"from": 14.5, "to": 15.0}), "re-identified"),
        (dict(change="appears", after=_set("uncertain"), from_seeds=[5], **{"from": 17.5, "to": 18.0}), "split"),
        (dict(change="appears", after=_set("chaotic"), from_seeds=[2, 3], **{"from": 13.0, "to": 13.5}), "merging crisis"),
        (dict(change="becomes transient", long_before=_run(14, 0), long_after=_run(12, 12),
              **{"from": 18.0, "to": 18.5}), "boundary crisis"),
    ],
)
def test_explanations_of_constructed_changes(ev, cls):
    assert E.explain(ev, BIF, 64, PRESENT | {13.5: set(), 12.0: set(), 15.5: set(), 16.5: set(), 18.5: set(),
                                             19.5: set()})[0] == cls  # fmt: skip


def test_sampling_chance_is_binomial():
    ev = dict(change="appears", after=_set("chaotic", fraction=0.03125), **{"from": 12.5, "to": 13.0})
    cls, text = E.explain(ev, BIF, 64, {13.0: set()})
    assert cls == "sampling" and f"{(1 - 0.03125) ** 64:.2f}" in text  # (1 - f)^N, f = 2/64: 0.13


def test_committed_result_explains_every_change():
    d = json.loads((ROOT / "docs" / "orbits" / "attractor_events.json").read_text())
    assert d["events"], "no changes listed"
    assert all(e["class"] != "not explained" for e in d["events"])
    assert sum(d["classes"].values()) == len(d["events"])
