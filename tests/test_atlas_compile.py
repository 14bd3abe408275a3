"""The atlas compile benchmark's pure parts: its arguments, the per-part differences, the logged-compile summary.

No timing is run or asserted (machines differ); benchmarks/atlas_compile.py --smoke runs the measurement itself.
"""

import pathlib
import sys

import pytest

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "benchmarks"))

import atlas_compile as ac  # noqa: E402


def test_defaults_are_the_command_defaults():
    a = ac.parse_args([])
    assert a.reps == 2 and not a.smoke and a.out == pathlib.Path("docs/atlas/atlas_compile.json")
    # the measured run is `jaxcelt atlas` with no size options: its defaults
    assert ac.atlas_argv(pathlib.Path("D"), smoke=False) == ["atlas", "--out", "D"]
    smoke = ac.atlas_argv(pathlib.Path("D"), smoke=True)
    assert smoke[:3] == ["atlas", "--out", "D"] and "--no-branches" in smoke


def test_smoke_arguments_parse_with_the_command():
    # the smoke options are accepted by `jaxcelt atlas`'s own parser (a renamed option fails here, not after
    # minutes of a run)
    from jaxcelt.cli import build_parser

    args = build_parser().parse_args(ac.atlas_argv(pathlib.Path("D"), smoke=True))
    assert args.values == 2 and tuple(args.starts) == (4, 1) and args.no_branches


def test_reps_must_be_positive(capsys):
    with pytest.raises(SystemExit) as e:
        ac.parse_args(["--reps", "0"])
    assert e.value.code == 2 and "--reps" in capsys.readouterr().err


def test_part_seconds_difference():
    # exact arithmetic on hand-made numbers (rounded to 1 ms); a part absent from a run (not run) is left out
    first = dict(continuation=60.5, brute_force=4.25, spectrum=18.0, command=90.0, call=90.125)
    second = dict(continuation=20.0, brute_force=0.5, branches=3.0, spectrum=2.0, command=30.0, call=30.0)
    d = ac.part_seconds(first, second)
    assert set(d) == {"continuation", "brute_force", "spectrum", "command", "call"}
    assert d["continuation"] == dict(first_s=60.5, second_s=20.0, compile_s=40.5)
    assert d["brute_force"]["compile_s"] == 3.75 and d["call"]["compile_s"] == 60.125


def test_logged_summary():
    logged = [("tracing", "jit(a)", 0.5), ("tracing", "jit(b)", 0.1), ("lowering", "jit(a)", 0.3),
              ("xla", "jit(a)", 2.0), ("xla", "jit(b)", 0.1), ("xla", "jit(c)", 5.0)]  # fmt: skip
    s = ac.logged_summary(logged)
    assert s["tracing_s_over_0.2"] == 0.5 and s["tracing_s_all"] == 0.6
    assert s["lowering_s_over_0.2"] == 0.3 and s["xla_s_over_0.2"] == 7.0 and s["xla_s_all"] == 7.1
    assert s["programs_compiled"] == 3 and s["programs_over_0.2"] == 2
    assert s["top5_xla"] == [["jit(c)", 5.0], ["jit(a)", 2.0], ["jit(b)", 0.1]]


def test_medians_over_processes():
    def rep(c, x):
        lg = dict(xla_s_all=x, programs_compiled=3, top5_xla=[])
        return dict(parts=dict(continuation=dict(first_s=c + 1, second_s=1.0, compile_s=c)),
                    runs=[dict(logged=lg), dict(logged=lg)])  # fmt: skip

    m = ac.medians([rep(10.0, 1.0), rep(30.0, 2.0), rep(20.0, 9.0)])
    assert m["continuation"] == dict(first_s=21.0, second_s=1.0, compile_s=20.0)
    assert m["logged_first_run"] == dict(xla_s_all=2.0, programs_compiled=3)
