"""Benchmark: ``tablebot evolve``'s throughput, as the whole command a user waits for and as its inner parts.

Run: ``.venv/bin/python benchmarks/evolve.py [--repeat 3] [--quick]``.

* **whole process**: ``tablebot evolve examples/bumberbot --budget B --seeds 0..15 --seconds 30`` in a fresh
  process (imports, the repair, proofs, the fleet, the fresh-seed check and every file written):
  candidates (tables) per second and robot-ticks per second of the search (the tables its report says it
  ran × scenarios × ticks, over the wall time and over the time it waited for the fleet), with where the
  time went as the run's report says (proofs, repair, waiting for the fleet);
* **inner evaluation**: 32 proved children of the repaired BumberBot, each on the same 16 scenarios,
  through the local backend kept open and warm (what one generation costs), beside the baseline of the
  same robots as *one* fleet of the starting table (``sweep``'s unit of work: one program, no pose
  samples): the ratio is what one fleet per table and the sampled poses cost;
* **proving**: proofs per second of fresh children (no cache), the price of a candidate before it runs;
* **whole / inner**: the whole process's candidates/s and robot-ticks/s against the inner loop's.

Medians of the repeats; ratios against baselines of the same run. The machine this was written on has
2 cores shared with other engineers' runs: compare ratios, not times.
"""

from __future__ import annotations

import argparse
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "bumberbot"


def whole(budget: int, seconds: float) -> dict[str, float]:
    """One run of the command in a fresh process; the tables it ran and their robot-ticks from its report
    (the search may end before the budget), the fresh-seed check after the search not counted."""
    with tempfile.TemporaryDirectory() as folder:
        command = [sys.executable, "-m", "tablebot", "evolve", str(EXAMPLE), "--out", folder, "--budget", str(budget),
                   "--batch", "16", "--seeds", "0..15", "--check-seeds", "100..115", "--seconds", str(seconds),
                   "--quiet"]
        started = time.perf_counter()
        subprocess.run(command, check=True, capture_output=True)
        wall = time.perf_counter() - started
        report = (Path(folder) / "report.md").read_text(encoding="utf-8")
    proofs = float(re.search(r"Proofs: \d+ run \(([\d.]+) s\)", report)[1])  # type: ignore[index]
    repair = float(re.search(r"Repair ([\d.]+) s", report)[1])  # type: ignore[index]
    fleet = float(re.search(r"waiting for the fleet ([\d.]+) s", report)[1])  # type: ignore[index]
    ran = re.search(r"(\d+) tables run on the fleet, each on (\d+) scenarios", report)
    tables, scenarios = int(ran[1]), int(ran[2])  # type: ignore[index]
    ticks = tables * scenarios * ticks_of(seconds)
    return {"wall": wall, "tables": tables, "tables/s": tables / wall, "robot-ticks/s": ticks / wall,
            "fleet robot-ticks/s": ticks / fleet, "proofs": proofs, "repair": repair, "fleet": fleet}


def ticks_of(seconds: float) -> int:
    """Ticks of one run of ``seconds`` (the robot file's tick, as the command plans it)."""
    from tablebot.fleet.plan import make_plan

    return make_plan(EXAMPLE, None, [], ["start=random"], "0..0", None, seconds).spec.ticks


def children(count: int) -> tuple[object, list[tuple[str, object]], object]:
    """``count`` proved children of the repaired BumberBot (distinct behaviours), as tables."""
    import numpy as np

    from tablebot.analysis.properties import find_property_files
    from tablebot.evolve import space
    from tablebot.evolve.operators import Space, vary
    from tablebot.evolve.proofs import Prover
    from tablebot.evolve.repair import repair
    from tablebot.formats.table_read import load_table

    table = load_table(EXAMPLE / "table.csv")
    limits = space.Limits(space.default_max_rows(table), timer_max=space.default_timer_max(table))
    sp = Space(table.states, table.robot.motors, limits)
    prover = Prover(find_property_files(EXAMPLE / "table.csv"))
    seed = repair(space.start(table), table, prover, sp).candidate
    rng = np.random.default_rng(0)
    out: dict[str, object] = {}
    while len(out) < count:
        child = vary(seed, sp, rng)
        key, verdict = prover.verdict(space.to_table(child, table))  # type: ignore[arg-type]
        if verdict.ok:
            out.setdefault(key, space.to_table(child, table))  # type: ignore[arg-type]
    return table, list(out.items()), sp


def inner(repeat: int, count: int, seconds: float) -> dict[str, float]:
    from tablebot.evolve.evaluate import Evaluator
    from tablebot.fleet.backends import Runner
    from tablebot.fleet.plan import make_plan
    from tablebot.fleet.spec import runs
    from tablebot.fleet.work import Job, run_job

    plan = make_plan(EXAMPLE, None, [], ["start=random"], "0..15", None, seconds)
    _, tables, _ = children(count)
    robots = [plan.robot(run) for run in runs(plan.spec)]
    ticks = count * len(robots) * plan.spec.ticks
    with Runner("local") as runner:
        evaluator = Evaluator(plan, runner, ["time_to_lamp", "area_covered", "collision_share"])
        evaluator.run(tables[:2], lambda *a: None)  # start and warm the workers
        evolve_s, fleet_s = [], []
        for _ in range(repeat):
            started = time.perf_counter()
            evaluator.run(tables, lambda *a: None)
            evolve_s.append(time.perf_counter() - started)
            jobs = [Job(plan.table, plan.worlds[0], plan.robot_params, robots * 4, plan.spec.ticks, first=k)
                    for k in range(count // 4)]  # the same robot-ticks, one program, 64 robots a job
            started = time.perf_counter()
            runner.run(jobs, lambda *a: None, run_job)
            fleet_s.append(time.perf_counter() - started)
    e, f = statistics.median(evolve_s), statistics.median(fleet_s)
    print(f"inner loop (evaluation only), {count} tables × {len(robots)} scenarios × {seconds:g} s on the warm local "
          f"backend, median of {repeat}: {count / e:.1f} candidates/s, {ticks / e / 1e6:.2f} M robot-ticks/s "
          f"({spread([count / t for t in evolve_s])} candidates/s); baseline, the same robot-ticks as plain fleets "
          f"of one table: {ticks / f / 1e6:.2f} M robot-ticks/s; inner/baseline = {f / e:.2f}×")
    return {"candidates/s": count / e, "robot-ticks/s": ticks / e}


def spread(values: list[float]) -> str:
    return f"{min(values):.2f}..{max(values):.2f}" if len(values) > 1 else f"{values[0]:.2f}"


def proving(count: int) -> None:
    import numpy as np

    from tablebot.analysis.properties import find_property_files
    from tablebot.evolve import space
    from tablebot.evolve.operators import vary
    from tablebot.evolve.proofs import Prover

    table, tables, sp = children(1)
    prover = Prover(find_property_files(EXAMPLE / "table.csv"))
    seed = space.start(tables[0][1])  # type: ignore[arg-type]
    rng = np.random.default_rng(1)
    kids = [space.to_table(vary(seed, sp, rng), table) for _ in range(count)]  # type: ignore[arg-type]
    started = time.perf_counter()
    kept = sum(prover.verdict(kid)[1].ok for kid in kids)
    took = time.perf_counter() - started
    print(f"proving: {count} children in {took:.2f} s ({count / took:.0f} proofs/s incl. cache hits: "
          f"{prover.proved} proved, {prover.hits} from the cache), {kept} kept")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="smaller runs, one repeat")
    args = parser.parse_args()
    repeat = 1 if args.quick else args.repeat
    budget, seconds = (32, 10.0) if args.quick else (96, 30.0)
    runs = [whole(budget, seconds) for _ in range(repeat)]
    med = {key: statistics.median(r[key] for r in runs) for key in runs[0]}
    print(f"whole process (what the user waits for): tablebot evolve examples/bumberbot --budget {budget}, 16 "
          f"scenarios × {seconds:g} s, median of {repeat}: {med['wall']:.1f} s for {med['tables']:.0f} tables, "
          f"{med['tables/s']:.2f} candidates/s ({spread([r['tables/s'] for r in runs])}), "
          f"{med['robot-ticks/s'] / 1e6:.3f} M robot-ticks/s of search per wall second, "
          f"{med['fleet robot-ticks/s'] / 1e6:.3f} M per second waiting for the fleet; of the wall time: proofs "
          f"{med['proofs'] / med['wall']:.0%}, repair {med['repair'] / med['wall']:.0%}, waiting for the fleet "
          f"{med['fleet'] / med['wall']:.0%} (the rest: start-up, the fresh-seed check, the files)")
    loop = inner(repeat, 16 if args.quick else 32, seconds)
    print(f"whole process / inner loop: {med['tables/s'] / loop['candidates/s']:.2f}× in candidates/s, "
          f"{med['robot-ticks/s'] / loop['robot-ticks/s']:.2f}× in robot-ticks/s")
    proving(100 if args.quick else 300)


if __name__ == "__main__":
    main()
