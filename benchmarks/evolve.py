"""Benchmark: ``tablebot evolve``'s throughput, as the whole command a user waits for and as its inner parts.

Run: ``.venv/bin/python benchmarks/evolve.py [--repeat 3] [--quick]``.

* **whole process**: ``tablebot evolve examples/bumberbot --budget B --seeds 0..15 --seconds 30`` in a fresh
  process (imports, the repair, proofs, the fleet, the fresh-seed check and every file written):
  tables per second and robot-ticks per second of the search (B tables × scenarios × ticks over the wall
  time), with where the time went as the run's report says (proofs, repair, waiting for the fleet);
* **inner evaluation**: 32 proved children of the repaired BumberBot, each on the same 16 scenarios,
  through the local backend kept open and warm (what one generation costs), beside the baseline of the
  same robots as *one* fleet of the starting table (``sweep``'s unit of work: one program, no pose
  samples): the ratio is what one fleet per table and the sampled poses cost;
* **proving**: proofs per second of fresh children (no cache), the price of a candidate before it runs.

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
    ticks = budget * 16 * round(seconds / 0.010)
    return {"wall": wall, "tables/s": budget / wall, "robot-ticks/s": ticks / wall, "proofs": proofs,
            "repair": repair, "fleet": fleet}


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


def inner(repeat: int, count: int, seconds: float) -> None:
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
    print(f"inner evaluation, {count} tables × {len(robots)} scenarios × {seconds:g} s, local backend warm: "
          f"{count / e:.1f} tables/s, {ticks / e / 1e6:.2f} M robot-ticks/s; the same robot-ticks as one table's "
          f"fleets: {ticks / f / 1e6:.2f} M/s; evolve/plain = {f / e:.2f}×")


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
    print(f"whole process: tablebot evolve, {budget} tables × 16 scenarios × {seconds:g} s: {med['wall']:.1f} s, "
          f"{med['tables/s']:.2f} tables/s, {med['robot-ticks/s'] / 1e6:.2f} M robot-ticks/s of search; of the wall "
          f"time: proofs {med['proofs'] / med['wall']:.0%}, repair {med['repair'] / med['wall']:.0%}, "
          f"waiting for the fleet {med['fleet'] / med['wall']:.0%}")
    inner(repeat, 16 if args.quick else 32, seconds)
    proving(100 if args.quick else 300)


if __name__ == "__main__":
    main()
