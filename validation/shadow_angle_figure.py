"""Shadow angles of the cliff_talus_runout scenario: stop points against the Evans & Hungr (1993) rule.

    python validation/shadow_angle_figure.py [--n 4000] [--seed 1]

Runs the shipped scenario (materials: the bedrock, talus and meadow presets), computes
the shadow angle of every stopped block -- the angle below the horizontal from the top
of the talus (x = 15.58 m, z = 60 m) to the stop point (Evans & Hungr 1993, Can.
Geotech. J. 30:620-636) -- prints its distribution and writes, deterministically for a
given seed:

* ``simulation/scenarios/figures/cliff_talus_runout_shadow.png``: the profile, the stop points, 10 simulated
  trajectories, the 27.5 deg shadow line (Wyllie 2014, figure 1.1) and the 22 and 30 deg
  lines bounding Evans & Hungr's minimum shadow angles; beside it the histogram of
  shadow angles;
* ``simulation/scenarios/figures/cliff_talus_runout_shadow.csv``: the distribution (quantiles, shares).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(REPO))

import simulation  # noqa: E402

SCENARIOS = REPO / "simulation" / "scenarios"

TALUS_TOP = (15.58, 60.0)          # x, z [m]
TALUS_TOE_X = 101.269              # m


def shadow_angles(result):
    """(shadow angle [deg], x [m], z [m]) of the stopped blocks."""
    pb = result.per_block
    stopped = pb["reason"] == 1
    x, z = pb["x"][stopped], pb["z"][stopped]
    return np.degrees(np.arctan2(TALUS_TOP[1] - z, x - TALUS_TOP[0])), x, z


def distribution(angle, x, n):
    q = np.percentile(angle, [0, 1, 5, 10, 25, 50, 75])
    return pd.Series({"blocks": n, "stopped": angle.size, "min_deg": q[0], "p1_deg": q[1], "p5_deg": q[2],
                      "p10_deg": q[3], "p25_deg": q[4], "median_deg": q[5], "p75_deg": q[6],
                      "share_below_27.5": float(np.mean(angle < 27.5)), "share_below_22": float(np.mean(angle < 22)),
                      "share_on_talus": float(np.mean(x <= TALUS_TOE_X)),
                      "share_within_20m_of_toe": float(np.mean(x <= TALUS_TOE_X + 20))})


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=4000)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    sc = simulation.load_scenario(SCENARIOS / "cliff_talus_runout.toml")
    res = simulation.run(sc, n=args.n, seed=args.seed, record_paths=10)
    angle, x, z = shadow_angles(res)
    dist = distribution(angle, x, args.n)
    print(dist.round(3).to_string())
    out = SCENARIOS / "figures"
    out.mkdir(exist_ok=True)
    dist.to_frame("value").to_csv(out / "cliff_talus_runout_shadow.csv")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from simulation.plotting import plot_profile
    fig, (ax, axh) = plt.subplots(1, 2, figsize=(13, 4.8), gridspec_kw={"width_ratios": [2.6, 1]})
    plot_profile(res, ax=ax, n_paths=10)
    xs = np.array([TALUS_TOP[0], 260.0])
    for a, style, label in ((27.5, dict(color="C3", lw=1.8), "27.5° shadow line (Wyllie 2014, fig. 1.1)"),
                            (22.0, dict(color="C3", lw=0.9, ls=":"), "22° and 30° (Evans & Hungr 1993 range)"),
                            (30.0, dict(color="C3", lw=0.9, ls=":"), None)):
        ax.plot(xs, TALUS_TOP[1] - np.tan(np.radians(a)) * (xs - TALUS_TOP[0]), label=label, **style)
    ax.plot(x, z, "|", color="k", ms=8, alpha=0.3, label=f"stop points ({x.size} blocks)")
    ax.set_xlim(-5, 260)
    ax.set_ylim(-5, 125)
    ax.legend(fontsize="small", loc="upper right")
    ax.set_title("cliff_talus_runout: presets bedrock / talus / meadow")
    axh.hist(angle, bins=np.arange(20, 36.01, 0.5), color="0.5")
    axh.axvline(27.5, color="C3", lw=1.8)
    axh.axvspan(22, 30, color="C3", alpha=0.1, label="22-30°: minimum shadow angles\n(Evans & Hungr 1993)")
    axh.set_xlabel("shadow angle from the talus top [deg]")
    axh.set_ylabel("stopped blocks")
    axh.set_title(f"min {dist.min_deg:.1f}°, median {dist.median_deg:.1f}°; "
                  f"{dist['share_below_27.5']:.1%} below 27.5°", fontsize="small")
    axh.legend(fontsize="small", loc="upper left")
    fig.tight_layout()
    fig.savefig(out / "cliff_talus_runout_shadow.png", dpi=100)
    plt.close(fig)
    print(f"wrote {out / 'cliff_talus_runout_shadow.png'}")


if __name__ == "__main__":
    main()
