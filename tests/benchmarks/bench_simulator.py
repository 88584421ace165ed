"""Benchmark: simulator throughput.

Run: python tests/benchmarks/bench_simulator.py [--million] [--baseline REV] [--rounds R] [--only-baseline]

Prints each target beside its figure with PASS/FAIL:

* cost flat in the number of segments (ratio 200 / 5 segments >= 0.7), measured two ways:
  - per kernel event on the peer profile with a real slope change at every vertex (a random 0.05-0.1 deg
    bend, alternating in sign), so no segments are collinear and none merge into runs: the impact search
    and the contact phase see all 5 or 200 segments.  Per impact this profile is NOT flat, and the script
    says so: a block rolling in contact crosses every vertex as an exact constant-acceleration step, so the
    events per impact grow with the vertices crossed;
  - per impact on the peer-profile benchmark, the peer profile cut into collinear pieces (they merge back into
    the 5 original runs, so it mostly tests that merging).
* the shipped barrier scenario (road_cut_barrier.toml) >= 200,000 trajectories per CPU-second on one core.
* side by side with an earlier commit (``--baseline``, default 06331e7, the last commit before rolling drag and the
  steep-face rule; ``--baseline none`` skips it): the peer profile (and the barrier scenario) timed in two child
  processes, one importing this tree's ``simulation`` and one a ``git worktree`` of REV (made under /tmp on
  first use; both on this environment's numpy and numba), interleaved over ``--rounds`` rounds (the order
  alternating); the ratio now / REV per round and its median, >= 1 required on the peer profile.
* the peer-profile kernel at >= 0.7 of its realistic per-core ceiling.  The ceiling is measured in the same run
  (see ``floor_kernel``): the research note's physical-limit argument (shared/research/rockfall-simulation.md,
  section 3.3) made executable -- a compiled loop doing, for each block, as many impacts as that block had in
  the real run and as many contact steps as a recorded sample of blocks had, each impact only the irreducible
  arithmetic of one (the parabola-line quadratic with its square root, one uniform draw and the sine/cosine pair
  of the tilted surface, one normal deviate and one power for the restitution law, the frame changes), each
  contact step a square root and a division, with the state carried from one event to the next (latency, not
  throughput).  No bookkeeping, no search over segments, no collectors, no output: what no kernel of this model
  can avoid.  Its trajectories per CPU-s is the ceiling; the ratio is the kernel's trajectories/s over it,
  the kernel's calls timed alone (CPU seconds inside ``kernel.simulate``).  The share of the whole
  ``simulation.run`` (which also draws the releases with numpy's generators and builds the tables) is printed
  beside it.

Also printed: the collinear resampling (5, 10, 200, 1,000 segments), a ground jittered by up to 2 cm
(rolling blocks hop over its vertices) and with --million a 1,000,000-block run with its peak memory.
Times are CPU time of this process (time.process_time; the simulator runs on one thread), which a loaded
shared machine disturbs less than wall time; the best of --repeat runs is reported.  One process; the
kernel is compiled (and cached) before timing.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

import simulation
from simulation.slope import Profile

SCENARIOS = Path(simulation.__file__).parent / "scenarios"
TREE = Path(__file__).resolve().parents[2]      # the repository this script belongs to


def resampled(scenario, n_segments):
    """The same ground line cut into n_segments pieces (vertices added on the existing segments)."""
    prof = scenario.profile
    s = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(prof.x), np.diff(prof.z)))])
    t = np.unique(np.concatenate([s, np.linspace(0.0, s[-1], n_segments + 1)]))
    # keep exactly n_segments segments: merge extra vertices by taking n_segments+1 points including originals
    if t.size > n_segments + 1:
        extra = np.setdiff1d(t, s)
        keep = np.sort(np.concatenate([s, extra[np.linspace(0, extra.size - 1, n_segments + 1 - s.size).astype(int)]]))
        t = keep
    x, z = np.interp(t, s, prof.x), np.interp(t, s, prof.z)
    mats = prof.material_index[np.clip(np.searchsorted(prof.x, 0.5 * (x[:-1] + x[1:])) - 1, 0, None)]
    return replace(scenario, profile=Profile.build(x, z, mats, prof.material_names))


def bent(scenario, n_segments, seed=0):
    """The peer ground cut into n_segments pieces with a small slope change at every vertex: each segment's
    angle differs from the previous one's by 0.05-0.1 deg (alternating sign, random size), so no two
    neighbours are collinear (none merge into runs) and the ground stays within 0.11 m of the peer profile
    (1 cm at 200 segments; a bend this small does not launch a rolling block)."""
    sc = resampled(scenario, n_segments)
    x, z = sc.profile.x, sc.profile.z.copy()
    rng = np.random.default_rng(seed)
    angle = np.arctan2(np.diff(z), np.diff(x))
    bend = np.radians(rng.uniform(0.05, 0.1, angle.size)) * np.where(np.arange(angle.size) % 2, 1.0, -1.0)
    angle = angle + bend
    z = np.concatenate([[z[0]], z[0] + np.cumsum(np.diff(x) * np.tan(angle))])
    prof = Profile.build(x, z, sc.profile.material_index, sc.profile.material_names)
    assert (prof.run_first == np.arange(prof.n_segments)).all(), "some segments merged into runs"
    return replace(sc, profile=prof)


REPEAT = 3
TARGET_RATIO = 0.7                 # cost at 200 segments / at 5 segments (per event; per impact on the analytic-check profile)
TARGET_BARRIER = 200_000           # trajectories/s on the shipped barrier scenario, one core


def timed(scenario, n, seed=1):
    """The result and the best of REPEAT CPU timings [s] of this process (time.process_time: the simulator is
    single-threaded; on a shared machine CPU time moves less than wall time, and the minimum is the least
    disturbed run, as timeit reports)."""
    simulation.run(scenario, n=min(n, 1000), seed=seed)          # compile / warm up
    best = float("inf")
    for _ in range(REPEAT):
        t = time.process_time()
        res = simulation.run(scenario, n=n, seed=seed)
        best = min(best, time.process_time() - t)
    return res, best


_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)


def _floor_kernel_py(impacts, contacts, seed):
    """The realistic ceiling's work (module docstring): ``impacts[b]`` impacts and ``contacts[b]`` contact steps
    for block b, each with only its irreducible arithmetic, the state carried from event to event.  Returns a
    checksum (so the compiler cannot drop the work)."""
    g = 9.81
    state = np.uint64(seed)
    total = 0.0
    for b in range(impacts.shape[0]):
        x, z, vx, vz = 0.0, 1.5, 1.0 + 1e-3 * (b % 7), 0.0
        for _ in range(impacts[b]):
            # flight to the ground line z = slope x: the larger root of the parabola-line quadratic
            slope = -0.3
            c0 = z - slope * x
            c1 = vz - slope * vx
            t = (c1 + math.sqrt(c1 * c1 + 2.0 * g * abs(c0))) / g
            x += vx * t
            vz -= g * t
            z = slope * x
            # surface tilted by roughness: one uniform draw, one sine/cosine pair
            state = state + _GOLDEN
            q = state
            q = (q ^ (q >> np.uint64(30))) * _M1
            q = (q ^ (q >> np.uint64(27))) * _M2
            u = ((q ^ (q >> np.uint64(31))) >> np.uint64(11)) * (1.0 / 9007199254740992.0)
            bp = -0.29 + (2.0 * u - 1.0) * 0.1
            sb, cb = math.sin(bp), math.cos(bp)
            vn = -vx * sb + vz * cb
            vt = vx * cb + vz * sb
            # restitution law: one normal deviate (two uniforms, log, sqrt, cos) and one power
            state = state + _GOLDEN
            q = state
            q = (q ^ (q >> np.uint64(30))) * _M1
            q = (q ^ (q >> np.uint64(27))) * _M2
            u1 = ((q ^ (q >> np.uint64(31))) >> np.uint64(11)) * (1.0 / 9007199254740992.0)
            state = state + _GOLDEN
            q = state
            q = (q ^ (q >> np.uint64(30))) * _M1
            q = (q ^ (q >> np.uint64(27))) * _M2
            u2 = ((q ^ (q >> np.uint64(31))) >> np.uint64(11)) * (1.0 / 9007199254740992.0)
            dev = math.sqrt(-2.0 * math.log(max(u1, 1e-300))) * math.cos(2.0 * math.pi * u2)
            en = min(max(0.35 + 0.02 * dev, 0.0), 1.0) * (1.0 + abs(vn)) ** -0.03
            vn2 = -en * vn
            vt2 = 0.85 * vt
            # back to the profile frame; keep the state bounded (a new flight from a known height)
            vx = max(abs(vt2 * cb - vn2 * sb), 0.1)
            vz = min(vt2 * sb + vn2 * cb, 5.0)
            z += 0.5
        u_c = math.sqrt(vx * vx + vz * vz)
        for _ in range(contacts[b]):
            # a constant-acceleration step along a segment: end speed and time
            u_end = math.sqrt(max(u_c * u_c + 2.0 * 0.7 * 3.0, 0.0))
            x += (u_end - u_c) / 0.7
            u_c = 0.5 * u_end + 0.1
        total += x + u_c
    return total


def floor_kernel():
    """The compiled ceiling loop (:func:`_floor_kernel_py` under numba's njit)."""
    from numba import njit
    return njit(cache=False)(_floor_kernel_py)


def verdict(ok: bool) -> str:
    return "PASS" if ok else "FAIL"


def child() -> None:
    """``--child``: answer timing requests on stdin with this interpreter's ``simulation`` (PYTHONPATH picks the
    tree): one JSON line in (scenario, n, seed), one out (CPU seconds of ``simulation.run``, impacts, a checksum
    of the stop positions)."""
    loaded = {}
    # the CPU seconds inside the compiled kernel's calls too (kernel.simulate, through the module in both trees):
    # simulation.run also draws the releases (numpy's generators) and builds the tables around the kernel
    from simulation import kernel
    compiled, in_kernel = kernel.simulate, [0.0]

    def timed_simulate(*args, **kwargs):
        t0 = time.process_time()
        try:
            return compiled(*args, **kwargs)
        finally:
            in_kernel[0] += time.process_time() - t0
    kernel.simulate = timed_simulate
    print(json.dumps({"ready": simulation.__file__}), flush=True)
    for line in sys.stdin:
        req = json.loads(line)
        name = req["scenario"]
        if name not in loaded:
            loaded[name] = simulation.load_scenario(SCENARIOS / f"{name}.toml")
            simulation.run(loaded[name], n=1000, seed=1)          # compile or load the kernel, untimed
        in_kernel[0] = 0.0
        t = time.process_time()
        res = simulation.run(loaded[name], n=req["n"], seed=req["seed"])
        dt = time.process_time() - t
        print(json.dumps({"cpu_s": dt, "kernel_cpu_s": in_kernel[0], "impacts": int(res.n_impacts),
                          "x_sum": float(np.sum(res.per_block["x"]))}), flush=True)


def baseline_tree(rev: str) -> Path:
    """A detached ``git worktree`` of ``rev`` under /tmp (made on first use, reused after)."""
    full = subprocess.run(["git", "-C", str(TREE), "rev-parse", "--verify", f"{rev}^{{commit}}"], check=True,
                          capture_output=True, text=True).stdout.strip()
    where = Path(f"/tmp/riskrf-bench-{full[:12]}")
    if not (where / "simulation" / "__init__.py").exists():
        subprocess.run(["git", "-C", str(TREE), "worktree", "add", "--detach", str(where), full], check=True,
                       capture_output=True)
    return where


def _start_child(tree: Path):
    env = dict(os.environ, PYTHONPATH=str(tree))
    proc = subprocess.Popen([sys.executable, str(Path(__file__).resolve()), "--child"], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True, env=env, cwd="/tmp")
    ready = json.loads(proc.stdout.readline())["ready"]
    if not ready.startswith(str(tree)):
        raise RuntimeError(f"the child for {tree} imported {ready}")
    return proc


def _ask(proc, scenario: str, n: int, seed: int = 1) -> dict:
    proc.stdin.write(json.dumps({"scenario": scenario, "n": n, "seed": seed}) + "\n")
    proc.stdin.flush()
    return json.loads(proc.stdout.readline())


def ceiling_rate(scenario, n: int, repeat: int = 3) -> tuple[float, float, float]:
    """The realistic per-core ceiling on a scenario (module docstring): (trajectories per CPU-s, impacts per block,
    contact steps per block), the event counts from this tree's kernel (a run of n blocks for the impacts, a
    recorded sample of 2,000 blocks for the steps between them), the best of ``repeat`` timings."""
    res = simulation.run(scenario, n=n, seed=1)
    impacts = np.asarray(res.per_block["impacts"], dtype=np.int64)
    sample = simulation.run(scenario, n=2000, seed=1, record_paths=2000)
    ev = sample.paths["event"]
    steps_per_block = np.bincount(sample.paths["block"][(ev != 0) & (ev != 1)], minlength=2000)  # not release/impact
    contacts = np.resize(steps_per_block.astype(np.int64), n)
    floor = floor_kernel()
    floor(impacts[:10], contacts[:10], 1)                               # compile, untimed
    best = math.inf
    for _ in range(repeat):
        t = time.process_time()
        floor(impacts, contacts, 1)
        best = min(best, time.process_time() - t)
    return n / best, float(impacts.mean()), float(contacts.mean())


def side_by_side(rev: str, n: int, rounds: int) -> None:
    """This tree's kernel beside ``rev``'s, interleaved in two child processes, and the peer profile's share of
    its realistic ceiling (measured between the rounds in this process); prints each round and the medians."""
    old_tree = baseline_tree(rev)
    print(f"side by side: this tree {TREE} and {rev} at {old_tree}; {n:,} blocks per timing, {rounds} rounds "
          f"(order alternating), CPU seconds of simulation.run in each child; load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    procs = {"now": _start_child(TREE), rev: _start_child(old_tree)}
    peer = simulation.load_scenario(SCENARIOS / "peer_benchmark_profile.toml")
    try:
        for scenario in ("peer_benchmark_profile", "road_cut_barrier"):
            rates = {k: [] for k in procs}
            kernel_rates = []
            ceilings, same = [], True
            for i in range(rounds):
                order = list(procs) if i % 2 == 0 else list(procs)[::-1]
                got = {k: _ask(procs[k], scenario, n) for k in order}
                same &= got["now"]["impacts"] == got[rev]["impacts"] and got["now"]["x_sum"] == got[rev]["x_sum"]
                for k in procs:
                    rates[k].append(n / got[k]["cpu_s"])
                kernel_rates.append(n / got["now"]["kernel_cpu_s"])
                if scenario == "peer_benchmark_profile":
                    ceilings.append(ceiling_rate(peer, n, repeat=1))
            ratios = [a / b for a, b in zip(rates["now"], rates[rev])]
            print(f"{scenario}: trajectories per CPU-s now {[round(r) for r in rates['now']]}, "
                  f"{rev} {[round(r) for r in rates[rev]]}; now / {rev} per round {[round(r, 3) for r in ratios]}; "
                  f"identical stops: {same}")
            med = statistics.median(ratios)
            if scenario == "peer_benchmark_profile":
                print(f"TARGET peer profile at least as fast as {rev}, side by side: median now / {rev} = {med:.3f} "
                      f"(median {statistics.median(rates['now']):,.0f} against "
                      f"{statistics.median(rates[rev]):,.0f} trajectories/s; must be >= 1): {verdict(med >= 1.0)}")
                share = [r / c[0] for r, c in zip(kernel_rates, ceilings)]
                share_run = [r / c[0] for r, c in zip(rates["now"], ceilings)]
                share_old = [r / c[0] for r, c in zip(rates[rev], ceilings)]
                print(f"  realistic ceiling (floor kernel, {ceilings[0][1]:.2f} impacts and {ceilings[0][2]:.2f} "
                      f"contact steps per block): {[round(c[0]) for c in ceilings]} trajectories per CPU-s")
                print(f"  the kernel's calls alone: {[round(r) for r in kernel_rates]} trajectories per CPU-s; "
                      f"simulation.run's share of the ceiling (releases drawn and tables built around the kernel "
                      f"included) median {statistics.median(share_run):.2f} (per round "
                      f"{[round(x, 2) for x in share_run]}), {rev} {statistics.median(share_old):.2f}")
                print(f"TARGET peer-profile kernel at >= 0.7 of its realistic ceiling: median share of the kernel's "
                      f"calls {statistics.median(share):.2f} (per round {[round(x, 2) for x in share]}): "
                      f"{verdict(statistics.median(share) >= 0.7)}")
            else:
                print(f"  {scenario}: median now / {rev} = {med:.3f}")
    finally:
        for proc in procs.values():
            proc.stdin.close()
            proc.wait()
    print(f"load average after the side-by-side runs {os.getloadavg()[0]:.1f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--million", action="store_true", help="also run 1,000,000 blocks and report peak memory")
    ap.add_argument("-n", type=int, default=200_000, help="blocks per timing run (default 200,000)")
    ap.add_argument("--repeat", type=int, default=3, help="timings per case; the best is reported (default 3)")
    ap.add_argument("--baseline", default="06331e7", help="commit to time side by side with ('none': skip)")
    ap.add_argument("--rounds", type=int, default=5, help="interleaved rounds of the side-by-side timing (default 5)")
    ap.add_argument("--only-baseline", action="store_true", help="only the side-by-side timing and the ceiling")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        return child()
    global REPEAT
    REPEAT = args.repeat

    if args.baseline != "none":
        side_by_side(args.baseline, args.n, args.rounds)
        if args.only_baseline:
            return
    print(f"load average at start {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; {args.n:,} blocks per run, "
          f"best of {REPEAT} CPU timings")
    peer = simulation.load_scenario(SCENARIOS / "peer_benchmark_profile.toml")
    bent_rates, bent_events = {}, {}
    for segs in (5, 10, 200, 1000):
        sc = bent(peer, segs)
        res, dt = timed(sc, args.n)
        bent_rates[segs] = res.n_impacts / dt
        sample = simulation.run(sc, n=2000, seed=1, record_paths=2000)     # events per block, from a recorded sample
        events = sample.paths["block"].size / 2000
        bent_events[segs] = args.n * events / dt
        print(f"peer profile, {sc.profile.n_segments:>4} segments, a slope change at every vertex: {dt:.2f} CPU-s, "
              f"{res.n_impacts / args.n:.2f} impacts and {events:.1f} recorded events per block -> "
              f"{bent_rates[segs] / 1e6:.2f} M impacts/s ({bent_events[segs] / 1e6:.2f} M events/s), "
              f"{args.n / dt:,.0f} trajectories/s")
    ratio = bent_events[200] / bent_events[5]
    print(f"TARGET cost flat in the segments, per kernel event on the non-collinear profile: events/s at 200 / 5 "
          f"segments = {ratio:.2f} (must be >= {TARGET_RATIO}): {verdict(ratio >= TARGET_RATIO)}; 1,000 / 10 = "
          f"{bent_events[1000] / bent_events[10]:.2f}")
    print(f"  per impact on the same profile: impacts/s at 200 / 5 = {bent_rates[200] / bent_rates[5]:.2f}, "
          f"1,000 / 10 = {bent_rates[1000] / bent_rates[10]:.2f}: NOT flat, because a block rolling in contact crosses "
          "every vertex as an event (an exact constant-acceleration step on each segment), so the events per impact "
          "grow with the vertices crossed while the impacts per block stay the same; the search for the next impact "
          "is what stays O(log segments)")

    rates = {}
    for segs in (5, 10, 200, 1000):
        sc = resampled(peer, segs)
        res, dt = timed(sc, args.n)
        rates[segs] = res.n_impacts / dt
        print(f"peer profile, {sc.profile.n_segments:>4} collinear pieces (merged into 5 runs): "
              f"{rates[segs] / 1e6:.2f} M impacts/s, {args.n / dt:,.0f} trajectories/s")
    ratio = rates[200] / rates[5]
    print(f"TARGET cost per impact flat in the segments on the peer-profile benchmark (peer profile cut into collinear "
          f"pieces, which merge back into its 5 runs): impacts/s at 200 / 5 = {ratio:.2f} (must be >= {TARGET_RATIO}): "
          f"{verdict(ratio >= TARGET_RATIO)}; 1,000 / 10 = {rates[1000] / rates[10]:.2f}")
    # The same vertices moved by up to 2 cm: every vertex a slope change big enough to launch rolling blocks.
    rough_rates = {}
    for segs in (10, 200, 1000):
        sc = resampled(peer, segs)
        rng = np.random.default_rng(0)
        z = sc.profile.z + np.r_[0.0, rng.uniform(-0.02, 0.02, sc.profile.z.size - 2), 0.0]
        rough = replace(sc, profile=Profile.build(sc.profile.x, z, sc.profile.material_index,
                                                  sc.profile.material_names))
        res, dt = timed(rough, args.n)
        rough_rates[segs] = res.n_impacts / dt
        print(f"peer profile, {segs:>4} segments jittered by up to 2 cm: {res.n_impacts / args.n:.2f} impacts per "
              f"block -> {rough_rates[segs] / 1e6:.2f} M impacts/s, {args.n / dt:,.0f} trajectories/s")
    print(f"2 cm jitter impacts/s ratio, 1,000 / 200 segments = {rough_rates[1000] / rough_rates[200]:.2f}; "
          f"1,000 / 10 = {rough_rates[1000] / rough_rates[10]:.2f} (rolling blocks hop over the jittered vertices: "
          "more impacts per block and more contact events between them)")
    print("reference (rockfall-simulation.md 3.1, same profile, one core): PlatRock 0.4.6 ~700 trajectories/s, "
          "PyRockfall 0.1.2 ~760-1,130 trajectories/s")

    barrier = simulation.load_scenario(SCENARIOS / "road_cut_barrier.toml")
    res, dt = timed(barrier, args.n)
    tps = args.n / dt
    print(f"TARGET road_cut_barrier (shipped barrier scenario, envelopes on): {tps:,.0f} trajectories/s on one core "
          f"(must be >= {TARGET_BARRIER:,}): {verdict(tps >= TARGET_BARRIER)}; {res.n_impacts / dt / 1e6:.2f} M "
          "impacts/s")
    print(f"load average at end {os.getloadavg()[0]:.1f}")

    if args.million:
        t = time.perf_counter()
        res = simulation.run(barrier, n=1_000_000, seed=1)
        dt = time.perf_counter() - t
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        print(f"1,000,000 blocks: {dt:.1f} s, {len(res.collector('barrier')):,} barrier rows, "
              f"peak resident memory {peak:,.0f} MB")


if __name__ == "__main__":
    main()
