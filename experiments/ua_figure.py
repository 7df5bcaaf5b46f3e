#!/usr/bin/env python3
"""Issue 19's corridor figure: how a run's pose covariance and map point covariances grow where a direction is
not measured.

  experiments/ua_figure.py OUT.svg LABEL=RUN_DIR [LABEL=RUN_DIR ...]

Each RUN_DIR is an `mlidar slam` (or `odometry`) output with `mapping.uncertainty_aware: true`: the left panel draws
the 1-sigma of T_world_base's translation per world axis from RUN_DIR/pose_covariance.txt (README "Pose covariance")
against the frame; the right panel the distribution (share of points at or below) of tr(Sigma) of RUN_DIR/map.ply's
points (`cov_trace`). Needs numpy only; writes a self-contained SVG.
"""
import sys

import numpy as np

PLY_TYPES = {"float": "<f4", "double": "<f8", "uchar": "u1", "char": "i1", "ushort": "<u2", "short": "<i2",
             "uint": "<u4", "int": "<i4"}
COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"]
AXIS_DASH = {0: "", 1: "6,3", 2: "2,3"}


def read_pose_sigmas(path):
    """1-sigma of x, y, z per frame: the first three diagonal entries of the upper triangle after the stamp."""
    rows = np.loadtxt(path, comments="#", ndmin=2)
    # Upper triangle of a 6x6 in row order: diagonal (i, i) sits at i * 6 - i * (i - 1) / 2.
    diagonal = [i * 6 - i * (i - 1) // 2 for i in range(3)]
    return np.sqrt(np.maximum(rows[:, 1:][:, diagonal], 0.0))


def read_cov_trace(path):
    with open(path, "rb") as f:
        header = []
        while True:
            line = f.readline().decode("ascii").strip()
            header.append(line)
            if line == "end_header":
                break
        if "format binary_little_endian 1.0" not in header:
            raise SystemExit(f"{path}: only binary little-endian PLY is read here")
        count = next(int(l.split()[2]) for l in header if l.startswith("element vertex"))
        fields = [(l.split()[2], PLY_TYPES[l.split()[1]]) for l in header if l.startswith("property")]
        if "cov_trace" not in [name for name, _ in fields]:
            raise SystemExit(f"{path}: no cov_trace property (run with mapping.uncertainty_aware: true)")
        points = np.frombuffer(f.read(), dtype=np.dtype(fields), count=count)
    return np.sort(points["cov_trace"].astype(float))


class Panel:
    """A plot area with log or linear axes mapped to SVG coordinates."""

    def __init__(self, x0, y0, width, height, xrange, yrange, xlog, ylog):
        self.x0, self.y0, self.w, self.h = x0, y0, width, height
        self.xr, self.yr, self.xlog, self.ylog = xrange, yrange, xlog, ylog

    def _t(self, v, lo, hi, log):
        if log:
            v, lo, hi = np.log10(v), np.log10(lo), np.log10(hi)
        return (np.asarray(v) - lo) / (hi - lo)

    def sx(self, x):
        return self.x0 + self.w * self._t(x, *self.xr, self.xlog)

    def sy(self, y):
        return self.y0 + self.h * (1.0 - self._t(y, *self.yr, self.ylog))

    def polyline(self, x, y, colour, dash=""):
        points = " ".join(f"{a:.1f},{b:.1f}" for a, b in zip(self.sx(x), self.sy(y)))
        dashed = f' stroke-dasharray="{dash}"' if dash else ""
        return f'<polyline fill="none" stroke="{colour}" stroke-width="1.6"{dashed} points="{points}"/>'

    def frame(self, title, xlabel, ylabel, xticks, yticks):
        out = [f'<rect x="{self.x0}" y="{self.y0}" width="{self.w}" height="{self.h}" fill="none" stroke="#444"/>',
               f'<text x="{self.x0 + self.w / 2}" y="{self.y0 - 10}" text-anchor="middle" font-weight="bold">{title}</text>',
               f'<text x="{self.x0 + self.w / 2}" y="{self.y0 + self.h + 36}" text-anchor="middle">{xlabel}</text>',
               f'<text transform="translate({self.x0 - 52},{self.y0 + self.h / 2}) rotate(-90)" text-anchor="middle">{ylabel}</text>']
        for t in xticks:
            x = self.sx(t)
            out.append(f'<line x1="{x:.1f}" y1="{self.y0 + self.h}" x2="{x:.1f}" y2="{self.y0 + self.h + 4}" stroke="#444"/>')
            out.append(f'<text x="{x:.1f}" y="{self.y0 + self.h + 17}" text-anchor="middle" font-size="11">{t:g}</text>')
        for t in yticks:
            y = self.sy(t)
            out.append(f'<line x1="{self.x0 - 4}" y1="{y:.1f}" x2="{self.x0 + self.w}" y2="{y:.1f}" stroke="#ddd"/>')
            out.append(f'<text x="{self.x0 - 7}" y="{y + 4:.1f}" text-anchor="end" font-size="11">{t:g}</text>')
        return out


def main(argv):
    if len(argv) < 3 or any("=" not in a for a in argv[2:]):
        raise SystemExit(__doc__)
    runs = [(a.split("=", 1)[0], a.split("=", 1)[1]) for a in argv[2:]]
    sigmas = {label: read_pose_sigmas(f"{run}/pose_covariance.txt") for label, run in runs}
    traces = {label: read_cov_trace(f"{run}/map.ply") for label, run in runs}

    frames = max(len(s) for s in sigmas.values())
    positive = np.concatenate([s[s > 0] for s in sigmas.values()])
    smin, smax = 10 ** np.floor(np.log10(positive.min())), 10 ** np.ceil(np.log10(positive.max()))
    alltr = np.concatenate(list(traces.values()))
    tmin, tmax = 10 ** np.floor(np.log10(max(alltr.min(), 1e-9))), 10 ** np.ceil(np.log10(alltr.max()))

    left = Panel(80, 50, 380, 260, (0, frames - 1), (smin, smax), False, True)
    right = Panel(570, 50, 380, 260, (tmin, tmax), (0.0, 1.0), True, False)
    body = left.frame("Pose 1-sigma per world axis", "frame", "sigma (m)", list(range(0, frames, max(1, 5 * round(frames / 20)))),
                      [10.0 ** e for e in range(int(np.log10(smin)), int(np.log10(smax)) + 1)])
    body += right.frame("Map points' tr(Sigma)", "tr(Sigma) (m^2)", "share of points at or below",
                        [10.0 ** e for e in range(int(np.log10(tmin)), int(np.log10(tmax)) + 1)], [0, 0.25, 0.5, 0.75, 1])
    legend_y = 372
    for k, (label, _) in enumerate(runs):
        colour = COLOURS[k % len(COLOURS)]
        s = sigmas[label]
        for axis in range(3):
            keep = s[:, axis] > 0
            body.append(left.polyline(np.arange(len(s))[keep], s[keep, axis], colour, AXIS_DASH[axis]))
        t = traces[label]
        shares = np.linspace(0.0, 1.0, 201)  # the distribution at 200 quantiles: a small file for any map size
        body.append(right.polyline(np.maximum(np.quantile(t, shares), tmin), shares, colour))
        body.append(f'<text x="{80 + 300 * k}" y="{legend_y}" fill="{colour}">{label} (median tr {np.median(t):.4f} m^2)</text>')
    body.append(f'<text x="80" y="{legend_y + 20}" font-size="11">left panel: x solid, y dashed, z dotted</text>')
    svg = ['<svg xmlns="http://www.w3.org/2000/svg" width="1000" height="410" font-family="sans-serif" font-size="13">',
           '<rect width="100%" height="100%" fill="white"/>', *body, "</svg>"]
    with open(argv[1], "w") as f:
        f.write("\n".join(svg) + "\n")


if __name__ == "__main__":
    main(sys.argv)
