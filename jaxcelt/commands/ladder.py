"""``jaxcelt ladder``: run the ladder of contact laws on a built-in scene and recommend one."""

from __future__ import annotations

from jaxcelt.commands.args import UsageError, positive_float


def register(sub) -> None:
    p = sub.add_parser(
        "ladder", help="compare contact laws on a scene against the integral law; recommend the cheapest"
    )
    p.add_argument(
        "--scene", default="fast_spin", help="built-in scene: spin_reversal, base14, base19, fast_spin, or 'all'"
    )
    p.add_argument(
        "--tol", type=positive_float, default=0.05, help="relative error tolerance on the observed quantities"
    )
    p.add_argument("--laws", default=None, help="comma-separated rung names (default: the whole ladder)")
    p.add_argument("--short", action="store_true", help="halve the horizons")
    p.add_argument("--json", default=None, help="write results to this JSON file")
    p.set_defaults(func=run)


def run(args) -> int:
    from jaxcelt.studies.ladder import (
        builtin_scenes,
        default_ladder,
        needed_state,
        recommend,
        results_table,
        run_ladder,
    )

    scenes = builtin_scenes(short=args.short)
    names = list(scenes) if args.scene == "all" else [args.scene]
    for n in names:
        if n not in scenes:
            raise UsageError(f"argument --scene: unknown scene {n!r}; known: {', '.join(sorted(scenes))}, all")
    ladder = default_ladder()
    if args.laws:
        want = ["integral"] + [w for w in args.laws.split(",") if w != "integral"]
        known = {r.name: r for r in ladder}
        bad = [w for w in want if w not in known]
        if bad:
            raise UsageError(f"argument --laws: unknown law(s) {', '.join(bad)}; known: {', '.join(sorted(known))}")
        ladder = tuple(known[w] for w in want)
    results = {n: run_ladder(scenes[n], ladder) for n in names}
    print(results_table(results, args.tol))
    out = {}
    for n in names:
        need = needed_state(scenes[n])
        print(
            f"{n}: recommended {recommend(results[n], args.tol)}; state needed: {need['needed']}; droppable: {need['droppable']}"
        )
        out[n] = {
            "results": [r.as_dict() for r in results[n]],
            "recommended": recommend(results[n], args.tol),
            "state": need,
        }
    if args.json:
        from jaxcelt.provenance import write_result

        write_result(args.json, out)
    return 0
