"""Benchmark: how the simulator's compiled loops may take their data, each way timed on the same work.

Run: ``.venv/bin/python benchmarks/structures.py [--repeat 5] [--robots 10000] [--ticks 1000]``.

The work is the motors' and the pose's update of every tick (sim.physics.step.drive's arithmetic: battery volts
and charge, two motors with their lag, the midpoint heading) for many robots, on one thread, in four forms:

* **positional**: the robots' rows (float64, columns named by integer constants as in sim.columns) and their
  parameters passed as separate arrays -- the kernels' form before issue 35;
* **NamedTuple**: the same arrays in a NamedTuple (sim.physics.structures' form);
* **record, by field**: each robot a numpy record (a structured dtype), its fields read and written by name
  (``s.x``, ``p.kv``);
* **record, rows as views**: the same records, but the loop takes each robot's record once and works on it.

CPU time (``process_time``), the median of the repeats, as ns per robot-tick and as ratios to the positional
form measured in the same run; the forms must also agree to the last bit (they do the same arithmetic).
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from tablebot.jit import njit

# the robot's row (as sim.columns names its columns) and its parameters
X, Y, TH, V_R, V_L, SOC, GAIN_R, GAIN_L = range(8)
N_STATE = 8
P_DT, P_BASE, P_KV, P_VF, P_ALPHA, P_VFULL, P_VEMPTY, P_RINT, P_CAP, P_IIDLE, P_IMOTOR = range(11)
N_PARAM = 11
STATE_DTYPE = np.dtype([(name, np.float64) for name in ("x", "y", "th", "v_r", "v_l", "soc", "gain_r", "gain_l")])
PARAM_DTYPE = np.dtype(
    [
        (name, np.float64)
        for name in ("dt", "base", "kv", "vf", "alpha", "vfull", "vempty", "rint", "cap", "iidle", "imotor")
    ]
)
DUTY_R, DUTY_L = 0.75, 0.5  # the motor levels' duties (6/8 and 4/8), the same every tick

fast = njit(cache=False, refcounts=False)


class Robots(NamedTuple):
    S: np.ndarray
    P: np.ndarray


@fast
def _positional(S: np.ndarray, P: np.ndarray, ticks: int) -> float:
    for i in range(S.shape[0]):
        s, p = S[i], P[i]
        for _ in range(ticks):
            amps = p[P_IIDLE] + p[P_IMOTOR] * (DUTY_R + DUTY_L)
            volts = p[P_VEMPTY] + (p[P_VFULL] - p[P_VEMPTY]) * s[SOC] - amps * p[P_RINT]
            s[SOC] = max(0.0, s[SOC] - amps * p[P_DT] / p[P_CAP])
            s[V_R] += (s[GAIN_R] * p[P_KV] * max(0.0, DUTY_R * volts - p[P_VF]) - s[V_R]) * p[P_ALPHA]
            s[V_L] += (s[GAIN_L] * p[P_KV] * max(0.0, DUTY_L * volts - p[P_VF]) - s[V_L]) * p[P_ALPHA]
            turn = (s[V_R] - s[V_L]) / p[P_BASE] * p[P_DT]
            ahead = 0.5 * (s[V_R] + s[V_L]) * p[P_DT]
            mid = s[TH] + 0.5 * turn
            s[X] += ahead * math.cos(mid)
            s[Y] += ahead * math.sin(mid)
            s[TH] += turn
    return S[0, X]


@fast
def _named_tuple(robots: Robots, ticks: int) -> float:
    for i in range(robots.S.shape[0]):
        s, p = robots.S[i], robots.P[i]
        for _ in range(ticks):
            amps = p[P_IIDLE] + p[P_IMOTOR] * (DUTY_R + DUTY_L)
            volts = p[P_VEMPTY] + (p[P_VFULL] - p[P_VEMPTY]) * s[SOC] - amps * p[P_RINT]
            s[SOC] = max(0.0, s[SOC] - amps * p[P_DT] / p[P_CAP])
            s[V_R] += (s[GAIN_R] * p[P_KV] * max(0.0, DUTY_R * volts - p[P_VF]) - s[V_R]) * p[P_ALPHA]
            s[V_L] += (s[GAIN_L] * p[P_KV] * max(0.0, DUTY_L * volts - p[P_VF]) - s[V_L]) * p[P_ALPHA]
            turn = (s[V_R] - s[V_L]) / p[P_BASE] * p[P_DT]
            ahead = 0.5 * (s[V_R] + s[V_L]) * p[P_DT]
            mid = s[TH] + 0.5 * turn
            s[X] += ahead * math.cos(mid)
            s[Y] += ahead * math.sin(mid)
            s[TH] += turn
    return robots.S[0, X]


@fast
def _records(S: np.ndarray, P: np.ndarray, ticks: int) -> float:
    for i in range(S.shape[0]):
        for _ in range(ticks):
            amps = P[i].iidle + P[i].imotor * (DUTY_R + DUTY_L)
            volts = P[i].vempty + (P[i].vfull - P[i].vempty) * S[i].soc - amps * P[i].rint
            S[i].soc = max(0.0, S[i].soc - amps * P[i].dt / P[i].cap)
            S[i].v_r += (S[i].gain_r * P[i].kv * max(0.0, DUTY_R * volts - P[i].vf) - S[i].v_r) * P[i].alpha
            S[i].v_l += (S[i].gain_l * P[i].kv * max(0.0, DUTY_L * volts - P[i].vf) - S[i].v_l) * P[i].alpha
            turn = (S[i].v_r - S[i].v_l) / P[i].base * P[i].dt
            ahead = 0.5 * (S[i].v_r + S[i].v_l) * P[i].dt
            mid = S[i].th + 0.5 * turn
            S[i].x += ahead * math.cos(mid)
            S[i].y += ahead * math.sin(mid)
            S[i].th += turn
    return S[0].x


@fast
def _record_views(S: np.ndarray, P: np.ndarray, ticks: int) -> float:
    for i in range(S.shape[0]):
        s, p = S[i], P[i]
        for _ in range(ticks):
            amps = p.iidle + p.imotor * (DUTY_R + DUTY_L)
            volts = p.vempty + (p.vfull - p.vempty) * s.soc - amps * p.rint
            s.soc = max(0.0, s.soc - amps * p.dt / p.cap)
            s.v_r += (s.gain_r * p.kv * max(0.0, DUTY_R * volts - p.vf) - s.v_r) * p.alpha
            s.v_l += (s.gain_l * p.kv * max(0.0, DUTY_L * volts - p.vf) - s.v_l) * p.alpha
            turn = (s.v_r - s.v_l) / p.base * p.dt
            ahead = 0.5 * (s.v_r + s.v_l) * p.dt
            mid = s.th + 0.5 * turn
            s.x += ahead * math.cos(mid)
            s.y += ahead * math.sin(mid)
            s.th += turn
    return S[0].x


def robots(n: int) -> tuple[np.ndarray, np.ndarray]:
    """n BumberBots' rows and parameters (gains spread as the simulator draws them)."""
    rng = np.random.default_rng(1)
    S, P = np.zeros((n, N_STATE)), np.zeros((n, N_PARAM))
    S[:, SOC] = 1.0
    S[:, GAIN_R], S[:, GAIN_L] = 1.0 + 0.03 * rng.standard_normal((2, n))
    P[:] = (0.01, 0.1, 0.05, 0.7, 0.4, 9.6, 7.2, 0.5, 7200.0, 0.05, 0.25)
    return S, P


def as_records(S: np.ndarray, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return S.copy().view(STATE_DTYPE).reshape(len(S)), P.copy().view(PARAM_DTYPE).reshape(len(P))


def forms(n: int) -> dict[str, Callable[[int], np.ndarray]]:
    """Each form: a function of the ticks that runs them on fresh robots and returns their rows (flat)."""
    S, P = robots(n)

    def positional(ticks: int) -> np.ndarray:
        rows = S.copy()
        _positional(rows, P, ticks)
        return rows

    def named(ticks: int) -> np.ndarray:
        rows = S.copy()
        _named_tuple(Robots(rows, P), ticks)
        return rows

    def record(kernel: Any) -> Callable[[int], np.ndarray]:
        def run(ticks: int) -> np.ndarray:
            rows, params = as_records(S, P)
            kernel(rows, params, ticks)
            return rows.view(np.float64).reshape(n, N_STATE)

        return run

    return {
        "positional": positional,
        "NamedTuple": named,
        "record, by field": record(_records),
        "record, rows as views": record(_record_views),
    }


def cpu(run: Callable[[int], np.ndarray], ticks: int) -> float:
    started = time.process_time()
    run(ticks)
    return time.process_time() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--robots", type=int, default=10_000)
    parser.add_argument("--ticks", type=int, default=1_000)
    args = parser.parse_args()
    found = forms(args.robots)
    results = {name: run(10) for name, run in found.items()}  # compiled, and checked alike
    reference = results["positional"]
    for name, rows in results.items():
        assert np.array_equal(rows, reference), f"{name} differs from the positional form"
    times: dict[str, list[float]] = {name: [] for name in found}
    for _ in range(args.repeat):  # the forms alternate, so a busy machine slows them alike
        for name, run in found.items():
            times[name].append(cpu(run, args.ticks))
    work = args.robots * args.ticks
    base = statistics.median(times["positional"])
    print(
        f"{args.robots:,} robots x {args.ticks:,} ticks, one thread, CPU time, medians of {args.repeat}; "
        "every form's rows identical"
    )
    for name, spent in times.items():
        median = statistics.median(spent)
        print(f"  {name:<24} {median / work * 1e9:6.2f} ns per robot-tick   x{median / base:.2f} the positional form's")


if __name__ == "__main__":
    main()
