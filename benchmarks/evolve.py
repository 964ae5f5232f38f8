"""Benchmark: ``tablebot evolve``'s throughput, as the whole command a user waits for and as its inner loop.

Run: ``.venv/bin/python benchmarks/evolve.py [--repeat 3] [--quick] [--against OTHER/src]``.

* **whole process** (what the user waits for): ``tablebot evolve examples/bumberbot --budget B --seeds 0..15
  --seconds S`` in a fresh process (imports, the repair, proofs, the fleet, the fresh-seed check and every
  file written): wall seconds, candidates (tables) per second and robot-ticks per second of the search (the
  tables its report says it ran × scenarios × ticks, over the wall time), and the CPU seconds of its whole
  process tree (its proof workers included: on a shared machine CPU seconds move less than wall seconds);
  where the time went as the run's report says (proofs, repair, waiting for the fleet);
* **inner loop** (evaluation only): 16 (quick) or 32 proved children of the repaired BumberBot, each on the
  same 16 scenarios, through the local backend kept open and warm (what one generation's fleet costs),
  beside the baseline of the same robot-ticks as plain fleets of the starting table (``sweep``'s unit of
  work: one program, no pose samples);
* **proving**: proofs per second of fresh children in this process (no cache, no workers);
* **whole / inner**: the whole process's candidates/s and robot-ticks/s against the inner loop's.

``--against OTHER/src`` measures another tree's code (a checkout of main, say) the same way, each of its
runs right after one of this tree's, and prints this tree's figures over it (after/before). Medians of the
repeats; the load average is printed with the figures. The machine this was written on has 2 cores shared
with other engineers' runs: compare ratios of the same minute, not times of different days.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING, TypedDict

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "bumberbot"
NAMES = ["time_to_lamp", "area_covered", "collision_share"]


if TYPE_CHECKING:
    from tablebot.evolve.operators import Space
    from tablebot.table import Table

#: What the inner loop measures: its rates (medians) and the candidates/s of each repeat.
InnerRates = TypedDict(
    "InnerRates",
    {"candidates/s": float, "robot-ticks/s": float, "baseline robot-ticks/s": float, "spread": list[float]},
)


def environment(src: str | None) -> dict[str, str]:
    """This process's environment, with ``src`` (a tree's ``src`` folder) first on the path when given."""
    env = dict(os.environ)
    if src:
        env["PYTHONPATH"] = src
    return env


def tree_cpu(proc: subprocess.Popen) -> float:
    """CPU seconds (user + system) of ``proc`` and every process it starts, polled every 50 ms until it ends
    (the last 50 ms of each go uncounted)."""
    import psutil

    seen: dict[int, float] = {}
    root = psutil.Process(proc.pid)
    while proc.poll() is None:
        try:
            family = [root, *root.children(recursive=True)]
        except psutil.NoSuchProcess:
            break
        for p in family:
            try:
                times = p.cpu_times()
                seen[p.pid] = times.user + times.system
            except psutil.NoSuchProcess:
                pass
        time.sleep(0.05)
    return sum(seen.values())


def whole(budget: int, seconds: float, src: str | None = None) -> dict[str, float]:
    """One run of the command in a fresh process (``src``: another tree's code); the tables it ran and their
    robot-ticks from its report (the search may end before the budget), the fresh-seed check after the
    search not counted in them."""
    with tempfile.TemporaryDirectory() as folder:
        command = [
            sys.executable,
            "-m",
            "tablebot",
            "evolve",
            str(EXAMPLE),
            "--out",
            folder,
            "--budget",
            str(budget),
            "--batch",
            "16",
            "--seeds",
            "0..15",
            "--check-seeds",
            "100..115",
            "--seconds",
            str(seconds),
            "--quiet",
        ]
        started = time.perf_counter()
        proc = subprocess.Popen(command, env=environment(src), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        cpu = tree_cpu(proc)
        _, err = proc.communicate()
        wall = time.perf_counter() - started
        if proc.returncode:
            raise SystemExit(f"evolve failed ({proc.returncode}):\n{err.decode()}")
        report = (Path(folder) / "report.md").read_text(encoding="utf-8")
    proofs = float(re.search(r"Proofs: \d+ run \(([\d.]+) s\)", report)[1])  # type: ignore[index]
    repair = float(re.search(r"Repair ([\d.]+) s", report)[1])  # type: ignore[index]
    fleet = float(re.search(r"waiting for the fleet ([\d.]+) s", report)[1])  # type: ignore[index]
    ran = re.search(r"(\d+) tables run on the fleet, each on (\d+) scenarios", report)
    tables, scenarios = int(ran[1]), int(ran[2])  # type: ignore[index]
    ticks = tables * scenarios * ticks_of(seconds)
    return {
        "wall": wall,
        "cpu": cpu,
        "tables": tables,
        "tables/s": tables / wall,
        "robot-ticks/s": ticks / wall,
        "fleet robot-ticks/s": ticks / fleet,
        "proofs": proofs,
        "repair": repair,
        "fleet": fleet,
    }


def ticks_of(seconds: float) -> int:
    """Ticks of one run of ``seconds`` (the robot file's tick, as the command plans it)."""
    from tablebot.fleet.plan import make_plan

    return make_plan(EXAMPLE, None, [], ["start=random"], "0..0", None, seconds).spec.ticks


def children(count: int) -> tuple[Table, list[tuple[str, Table]], Space]:
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
    out: dict[str, Table] = {}
    while len(out) < count:
        child = vary(seed, sp, rng)
        key, verdict = prover.verdict(space.to_table(child, table))  # type: ignore[arg-type]
        if verdict.ok:
            out.setdefault(key, space.to_table(child, table))  # type: ignore[arg-type]
    return table, list(out.items()), sp


def inner(repeat: int, count: int, seconds: float) -> InnerRates:
    """The inner loop in this process: candidates/s and robot-ticks/s, and the plain-fleet baseline's."""
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
        evaluator = Evaluator(plan, runner, NAMES)
        evaluator.run(tables[:2], lambda *a: None)  # start and warm the workers
        evolve_s, fleet_s = [], []
        for _ in range(repeat):
            started = time.perf_counter()
            evaluator.run(tables, lambda *a: None)
            evolve_s.append(time.perf_counter() - started)
            jobs = [
                Job(plan.table, plan.worlds[0], plan.robot_params, robots * 4, plan.spec.ticks, first=k)
                for k in range(count // 4)
            ]  # the same robot-ticks, one program, 64 robots a job
            started = time.perf_counter()
            runner.run(jobs, lambda *a: None, run_job)
            fleet_s.append(time.perf_counter() - started)
    e, f = statistics.median(evolve_s), statistics.median(fleet_s)
    return {
        "candidates/s": count / e,
        "robot-ticks/s": ticks / e,
        "baseline robot-ticks/s": ticks / f,
        "spread": [count / t for t in evolve_s],
    }


def inner_process(repeat: int, count: int, seconds: float, src: str | None) -> InnerRates:
    """:func:`inner` in a fresh process of ``src``'s code (this tree's when None)."""
    done = subprocess.run(
        [sys.executable, __file__, "--inner-only", str(repeat), str(count), str(seconds)],
        env=environment(src),
        capture_output=True,
        text=True,
    )
    if done.returncode:
        raise SystemExit(f"the inner loop failed:\n{done.stderr}")
    return json.loads(done.stdout.splitlines()[-1])


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
    seed = space.start(tables[0][1])
    rng = np.random.default_rng(1)
    kids = [space.to_table(vary(seed, sp, rng), table) for _ in range(count)]  # type: ignore[arg-type]
    started = time.perf_counter()
    kept = sum(prover.verdict(kid)[1].ok for kid in kids)
    took = time.perf_counter() - started
    print(
        f"proving (in this process, no workers): {count} children in {took:.2f} s ({count / took:.0f} proofs/s "
        f"incl. cache hits: {prover.proved} proved, {prover.hits} from the cache), {kept} kept"
    )


def load() -> str:
    return "load average " + ", ".join(f"{x:.1f}" for x in os.getloadavg())


def say_whole(label: str, runs: list[dict[str, float]], budget: int, seconds: float) -> dict[str, float]:
    med = {key: statistics.median(r[key] for r in runs) for key in runs[0]}
    print(
        f"whole process (what the user waits for), {label}: tablebot evolve examples/bumberbot --budget {budget}, "
        f"16 scenarios × {seconds:g} s, median of {len(runs)}: {med['wall']:.1f} s for {med['tables']:.0f} tables, "
        f"{med['tables/s']:.2f} candidates/s ({spread([r['tables/s'] for r in runs])}), "
        f"{med['robot-ticks/s'] / 1e6:.3f} M robot-ticks/s of search per wall second; process tree CPU "
        f"{med['cpu']:.1f} s; of the wall time: proofs {med['proofs'] / med['wall']:.0%}, repair "
        f"{med['repair'] / med['wall']:.0%}, waiting for the fleet {med['fleet'] / med['wall']:.0%} (the rest: "
        f"start-up, the fresh-seed check, the files) [{load()}]"
    )
    return med


def say_inner(label: str, loop: InnerRates, count: int, seconds: float, repeat: int) -> None:
    print(
        f"inner loop (evaluation only), {label}: {count} tables × 16 scenarios × {seconds:g} s on the warm local "
        f"backend, median of {repeat}: {loop['candidates/s']:.1f} candidates/s "
        f"({spread(loop['spread'])}), {loop['robot-ticks/s'] / 1e6:.2f} M robot-ticks/s; baseline, the same "
        f"robot-ticks as plain fleets of one table: {loop['baseline robot-ticks/s'] / 1e6:.2f} M robot-ticks/s; "
        f"inner/baseline = {loop['robot-ticks/s'] / loop['baseline robot-ticks/s']:.2f}× [{load()}]"
    )


def main() -> None:
    if sys.argv[1:2] == ["--inner-only"]:
        repeat, count, seconds = int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4])
        print(json.dumps(inner(repeat, count, seconds)))
        return
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, help="runs of each (default 3, or 1 with --quick)")
    parser.add_argument("--quick", action="store_true", help="smaller runs (one of each unless --repeat)")
    parser.add_argument("--against", metavar="OTHER/src", help="another tree's src folder, measured alike")
    args = parser.parse_args()
    repeat = args.repeat or (1 if args.quick else 3)
    budget, seconds = (32, 10.0) if args.quick else (96, 30.0)
    count = 16 if args.quick else 32
    mine, theirs = [], []
    for _ in range(repeat):  # one after the other: both see the same minutes of a shared machine
        mine.append(whole(budget, seconds))
        if args.against:
            theirs.append(whole(budget, seconds, args.against))
    med = say_whole("this tree", mine, budget, seconds)
    loop = inner_process(repeat, count, seconds, None)
    say_inner("this tree", loop, count, seconds, repeat)
    print(
        f"whole process / inner loop: {med['tables/s'] / loop['candidates/s']:.2f}× in candidates/s, "
        f"{med['robot-ticks/s'] / loop['robot-ticks/s']:.2f}× in robot-ticks/s"
    )
    if args.against:
        old = say_whole(args.against, theirs, budget, seconds)
        old_loop = inner_process(repeat, count, seconds, args.against)
        say_inner(args.against, old_loop, count, seconds, repeat)
        print(
            f"this tree / {args.against} (after/before): whole process {old['wall'] / med['wall']:.2f}× as fast "
            f"({med['tables/s'] / old['tables/s']:.2f}× candidates/s, {old['cpu'] / med['cpu']:.2f}× less CPU); "
            f"inner loop {loop['candidates/s'] / old_loop['candidates/s']:.2f}× candidates/s"
        )
    proving(100 if args.quick else 300)


if __name__ == "__main__":
    main()
