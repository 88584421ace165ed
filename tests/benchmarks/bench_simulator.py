"""Benchmark: simulator throughput.

Run: python tests/benchmarks/bench_simulator.py [--million]

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

Also printed: the collinear resampling (5, 10, 200, 1,000 segments), a ground jittered by up to 2 cm
(rolling blocks hop over its vertices) and with --million a 1,000,000-block run with its peak memory.
Times are CPU time of this process (time.process_time; the simulator runs on one thread), which a loaded
shared machine disturbs less than wall time; the best of --repeat runs is reported.  One process; the
kernel is compiled (and cached) before timing.
"""
from __future__ import annotations

import argparse
import resource
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

import simulation
from simulation.slope import Profile

SCENARIOS = Path(simulation.__file__).parent / "scenarios"


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


def verdict(ok: bool) -> str:
    return "PASS" if ok else "FAIL"


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--million", action="store_true", help="also run 1,000,000 blocks and report peak memory")
    ap.add_argument("-n", type=int, default=200_000, help="blocks per timing run (default 200,000)")
    ap.add_argument("--repeat", type=int, default=3, help="timings per case; the best is reported (default 3)")
    args = ap.parse_args()
    global REPEAT
    REPEAT = args.repeat

    import os
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
