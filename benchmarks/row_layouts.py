"""Benchmark: a robot's state row read by name, two ways, against the flat row indexed by integer constants.

Run: ``.venv/bin/python benchmarks/row_layouts.py [--robots 2000] [--ticks 1000] [--rounds 9] [--history]``.

The work is a tick's battery, motors (lag, encoder, pulses) and pose (sim.physics.step.drive's arithmetic) for
every robot of a fleet, robot after robot as the fleet's loop runs them, one thread, in three layouts of the
robots' state (fifteen of a row's thirty columns are used):

* **flat**: each robot a float64 row indexed by sim.columns-style constants (the kernels before this);
* **record**: the same rows viewed as numpy records, read by field (``s.x``): sim.physics.layout's form;
* **per-field arrays**: a NamedTuple of one array per field across the robots (``s.x[i]``).

With ``--history`` each tick first copies the robot's row into a history (what a traced run keeps: the float
row copied column by column in the flat and record forms, the fields one by one in the per-field form).
Rounds alternate the layouts; CPU time (``process_time``), medians, as ns per robot-tick and as ratios to the
flat row in the same run. Every form must leave the same numbers (checked).

At load 8-13 on 2 cores (1,000-2,000 robots) the record was within noise of the flat row (x0.89-1.21 over runs)
and the per-field arrays a little slower (x1.02-1.26); yet the whole kernel converted to records (23d8e35) ran
x1.07-1.38 the flat rows' time in fresh processes (see f175ea0). The records were not the cause: that commit also
made each motor return its speed, encoder and pulses for the caller to store, and that alone, on the flat rows,
cost x1.15; with the motor writing each field as it is worked out the kernels read records at the flat rows'
speed (sim.physics.layout).
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from typing import Any, NamedTuple

import numpy as np

from tablebot.jit import njit

NAMES = (
    "x",
    "y",
    "th",
    "v_r",
    "v_l",
    "enc_r",
    "enc_l",
    "pul_r",
    "pul_l",
    "soc",
    "vbat",
    "amps",
    "dist",
    "gain_r",
    "gain_l",
)
X, Y, TH, V_R, V_L, ENC_R, ENC_L, PUL_R, PUL_L, SOC, VBAT, AMPS, DIST, GAIN_R, GAIN_L = range(len(NAMES))
N_STATE = 30
ROW = np.dtype([(n, "f8") for n in NAMES] + [("rest", "f8", (N_STATE - len(NAMES),))])
DT, BASE = 0.01, 0.15
fast = njit(cache=False, refcounts=False)


class Fields(NamedTuple):
    x: np.ndarray
    y: np.ndarray
    th: np.ndarray
    v_r: np.ndarray
    v_l: np.ndarray
    enc_r: np.ndarray
    enc_l: np.ndarray
    pul_r: np.ndarray
    pul_l: np.ndarray
    soc: np.ndarray
    vbat: np.ndarray
    amps: np.ndarray
    dist: np.ndarray
    gain_r: np.ndarray
    gain_l: np.ndarray


@njit(cache=False, inline="always")
def motor(gain: float, speed: float, enc: float, level: int, volts: float, noise: float) -> tuple[float, float, float]:
    target = np.sign(level) * gain * 0.05 * max(0.0, level / 8 * volts - 0.5) * (1.0 + 0.02 * noise)
    speed += (target - speed) * 0.3
    after = enc + abs(speed) * DT / 0.1 * 40
    return speed, after, math.floor(after) - math.floor(enc)


@njit(cache=False, inline="always")
def battery(soc: float, right: int, left: int) -> tuple[float, float, float]:
    amps = 0.1 + 0.5 * (abs(right) / 8 + abs(left) / 8)
    return amps, 7.0 + 2.0 * soc - amps * 0.3, max(0.0, soc - amps * DT / 3600.0)


@fast
def flat(S: np.ndarray, Z: np.ndarray, hist: np.ndarray, ticks: int) -> None:
    for i in range(S.shape[0]):
        s = S[i]
        for t in range(ticks):
            if hist.shape[0]:
                for j in range(s.shape[0]):
                    hist[t, j] = s[j]
            s[AMPS], s[VBAT], s[SOC] = battery(s[SOC], 8, 7)
            s[V_R], s[ENC_R], s[PUL_R] = motor(s[GAIN_R], s[V_R], s[ENC_R], 8, s[VBAT], Z[t, 0])
            s[V_L], s[ENC_L], s[PUL_L] = motor(s[GAIN_L], s[V_L], s[ENC_L], 7, s[VBAT], Z[t, 1])
            turn, ahead = (s[V_R] - s[V_L]) / BASE * DT, 0.5 * (s[V_R] + s[V_L]) * DT
            mid = s[TH] + 0.5 * turn
            s[X] += ahead * math.cos(mid)
            s[Y] += ahead * math.sin(mid)
            s[TH] += turn
            s[DIST] += abs(ahead)


@fast
def record(S: np.ndarray, Z: np.ndarray, hist: np.ndarray, ticks: int) -> None:
    for i in range(S.shape[0]):
        row = S[i]
        s = row.view(ROW)[0]
        for t in range(ticks):
            if hist.shape[0]:
                for j in range(row.shape[0]):
                    hist[t, j] = row[j]
            s.amps, s.vbat, s.soc = battery(s.soc, 8, 7)
            s.v_r, s.enc_r, s.pul_r = motor(s.gain_r, s.v_r, s.enc_r, 8, s.vbat, Z[t, 0])
            s.v_l, s.enc_l, s.pul_l = motor(s.gain_l, s.v_l, s.enc_l, 7, s.vbat, Z[t, 1])
            turn, ahead = (s.v_r - s.v_l) / BASE * DT, 0.5 * (s.v_r + s.v_l) * DT
            mid = s.th + 0.5 * turn
            s.x += ahead * math.cos(mid)
            s.y += ahead * math.sin(mid)
            s.th += turn
            s.dist += abs(ahead)


@fast
def per_field(s: Fields, Z: np.ndarray, hist: np.ndarray, ticks: int) -> None:
    for i in range(s.x.shape[0]):
        for t in range(ticks):
            if hist.shape[0]:
                for j, column in enumerate(s):  # unrolled by numba: a tuple of arrays of one type
                    hist[t, j] = column[i]
            s.amps[i], s.vbat[i], s.soc[i] = battery(s.soc[i], 8, 7)
            s.v_r[i], s.enc_r[i], s.pul_r[i] = motor(s.gain_r[i], s.v_r[i], s.enc_r[i], 8, s.vbat[i], Z[t, 0])
            s.v_l[i], s.enc_l[i], s.pul_l[i] = motor(s.gain_l[i], s.v_l[i], s.enc_l[i], 7, s.vbat[i], Z[t, 1])
            turn, ahead = (s.v_r[i] - s.v_l[i]) / BASE * DT, 0.5 * (s.v_r[i] + s.v_l[i]) * DT
            mid = s.th[i] + 0.5 * turn
            s.x[i] += ahead * math.cos(mid)
            s.y[i] += ahead * math.sin(mid)
            s.th[i] += turn
            s.dist[i] += abs(ahead)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, default=2000)
    parser.add_argument("--ticks", type=int, default=1000)
    parser.add_argument("--rounds", type=int, default=9)
    parser.add_argument("--history", action="store_true", help="copy each tick's row into a history first")
    args = parser.parse_args()
    start = np.zeros((args.robots, N_STATE))
    start[:, SOC], start[:, GAIN_R], start[:, GAIN_L] = 1.0, 1.0, 0.98
    Z = np.random.default_rng(1).standard_normal((args.ticks, 2))
    forms: dict[str, tuple[Any, Any]] = {
        "flat": (flat, lambda: start.copy()),
        "record": (record, lambda: start.copy()),
        "per-field arrays": (per_field, lambda: Fields(*(start[:, k].copy() for k in range(len(NAMES))))),
    }
    times: dict[str, list[float]] = {name: [] for name in forms}
    ends: dict[str, np.ndarray] = {}
    for r in range(args.rounds + 1):  # the first round compiles
        for name, (loop, make) in forms.items():
            state, hist = make(), np.zeros((args.ticks if args.history else 0, N_STATE))
            started = time.process_time()
            loop(state, Z, hist, args.ticks)
            if r:
                times[name].append(time.process_time() - started)
            ends[name] = np.stack(state, axis=1) if isinstance(state, Fields) else state[:, : len(NAMES)]
    assert all(np.array_equal(ends["flat"], end) for end in ends.values()), "the layouts left different numbers"
    base = statistics.median(times["flat"])
    print(f"{args.robots} robots x {args.ticks} ticks, {'with' if args.history else 'no'} history, one thread")
    for name, values in times.items():
        median = statistics.median(values)
        print(f"{name:<18} {median / (args.robots * args.ticks) * 1e9:7.1f} ns per robot-tick  x{median / base:.2f}")


if __name__ == "__main__":
    main()
