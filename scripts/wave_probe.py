"""The waves of a 2D flume run at a probe: their period and height.

    PYTHONPATH=build/python python3 scripts/wave_probe.py RUN_DIR PROBE_X [FROM_SECONDS]

Reads every frame of RUN_DIR (sph run -o RUN_DIR), takes the surface at x = PROBE_X as the
highest particle within 5 cm of it, and from FROM_SECONDS on (default 3: after the first waves
arrived) prints the times the surface rises through its mean (linearly interpolated between
frames), the periods between them, their mean, and the wave height (highest minus lowest
surface). docs/physics.md, "Moving obstacles", quotes it on scenes/examples/wave_flume_2d.json.
"""

import glob
import os
import sys

import numpy as np
import sph


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    run, probe = sys.argv[1], float(sys.argv[2])
    start = float(sys.argv[3]) if len(sys.argv) == 4 else 3.0
    files = sorted(glob.glob(os.path.join(run, "frames", "*.vtu")))
    if not files:
        sys.exit(f"no .vtu frames in {run}/frames (a run's directory, written with the vtu format)")
    times, surface = [], []
    for f in files:
        frame = sph.read_frame(f)
        x = frame["position"]
        near = np.abs(x[:, 0] - probe) < 0.05
        if not near.any():
            sys.exit(f"{f}: no particle within 5 cm of x = {probe}")
        times.append(frame["time"])
        surface.append(x[near, 1].max())
    t, s = np.array(times), np.array(surface)
    keep = t >= start
    t, e = t[keep], s[keep] - s[keep].mean()
    ups = [t[i] + (t[i + 1] - t[i]) * -e[i] / (e[i + 1] - e[i]) for i in range(len(e) - 1) if e[i] < 0 <= e[i + 1]]
    if len(ups) < 2:
        sys.exit(f"fewer than two up-crossings after {start} s: no waves to measure")
    periods = np.diff(ups)
    print("up-crossings (s):", " ".join(f"{u:.3f}" for u in ups))
    print("periods (s):     ", " ".join(f"{p:.3f}" for p in periods))
    print(f"mean period: {periods.mean():.4f} s; wave height: {e.max() - e.min():.4f} m")


if __name__ == "__main__":
    main()
