#!/usr/bin/env python3
"""Pair errors of an odometry run over BALM's Ouster keyframes (issue 18).

usage: balm_pairs.py RUN FIRST STEP [BALM_FOLDER]

RUN is an `mlidar odometry --scans ... --out RUN` folder over the keyframes
FIRST, FIRST + STEP, ... (in that order). For every consecutive pair k -> k+1
it compares the relative motion with the reference (alidarPose_*.csv),
E = (T_ref_k^-1 T_ref_k+1)^-1 (T_est_k^-1 T_est_k+1), and prints the median
pair error, the pairs over 10 cm or 1 deg ("bad") with whether the later
frame is flagged (suspect or lost in metrics.json), and writes the reference
as TUM (RUN/reference.tum, stamps as the run's) for `mlidar eval traj`.
Standard library only.
"""
import json
import math
import os
import sys


def read_balm(path):
    rows = [line.strip().rstrip(",") for line in open(path) if line.strip()]
    poses = []
    for k in range(0, len(rows), 4):
        m = [[float(v) for v in rows[k + r].split(",")] for r in range(4)]
        m[3][3] = 1.0  # the bottom-right element holds the stamp
        poses.append(m)
    return poses


def quat_to_matrix(qx, qy, qz, qw, x, y, z):
    n = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
    qx, qy, qz, qw = qx / n, qy / n, qz / n, qw / n
    return [[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw), x],
            [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw), y],
            [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy), z],
            [0, 0, 0, 1]]


def matrix_to_tum(m):
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0:
        s = 0.5 / math.sqrt(trace + 1.0)
        qw, qx, qy, qz = 0.25 / s, (m[2][1] - m[1][2]) * s, (m[0][2] - m[2][0]) * s, (m[1][0] - m[0][1]) * s
    else:
        i = max(range(3), key=lambda a: m[a][a])
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(1.0 + m[i][i] - m[j][j] - m[k][k])
        q = [0.0, 0.0, 0.0]
        q[i] = 0.25 * s
        q[j] = (m[j][i] + m[i][j]) / s
        q[k] = (m[k][i] + m[i][k]) / s
        qw = (m[k][j] - m[j][k]) / s
        qx, qy, qz = q
    return [m[0][3], m[1][3], m[2][3], qx, qy, qz, qw]


def mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def inv(m):
    r = [[m[j][i] for j in range(3)] for i in range(3)]
    t = [-sum(r[i][k] * m[k][3] for k in range(3)) for i in range(3)]
    return [r[0] + [t[0]], r[1] + [t[1]], r[2] + [t[2]], [0, 0, 0, 1]]


def pair_error(ref_a, ref_b, est_a, est_b):
    e = mul(inv(mul(inv(ref_a), ref_b)), mul(inv(est_a), est_b))
    translation = math.sqrt(sum(e[i][3] ** 2 for i in range(3)))
    cos = max(-1.0, min(1.0, (e[0][0] + e[1][1] + e[2][2] - 1.0) / 2.0))
    return translation, math.degrees(math.acos(cos))


def main():
    run, first, step = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    balm = sys.argv[4] if len(sys.argv) > 4 else os.path.join(os.path.dirname(__file__), "..", "..", "shared", "data", "real", "balm_ouster")
    reference = read_balm(os.path.join(balm, "alidarPose_0-49.csv")) + read_balm(os.path.join(balm, "alidarPose_50-119.csv"))
    est, stamps = [], []
    for line in open(os.path.join(run, "trajectory.tum")):
        if line.startswith("#") or not line.strip():
            continue
        t, x, y, z, qx, qy, qz, qw = (float(v) for v in line.split())
        stamps.append(t)
        est.append(quat_to_matrix(qx, qy, qz, qw, x, y, z))
    frames = json.load(open(os.path.join(run, "metrics.json")))["per_frame"]
    flagged = [f["lost"] or f["suspect"] for f in frames]
    ref = [reference[first + step * k] for k in range(len(est))]
    with open(os.path.join(run, "reference.tum"), "w") as out:
        for t, m in zip(stamps, ref):
            out.write("%.6f %s\n" % (t, " ".join("%.9f" % v for v in matrix_to_tum(m))))
    errors = [pair_error(ref[k], ref[k + 1], est[k], est[k + 1]) for k in range(len(est) - 1)]
    t_sorted = sorted(e[0] for e in errors)
    r_sorted = sorted(e[1] for e in errors)
    half = len(errors) // 2
    print("%d pairs, median %.2f cm / %.3f deg, %d frames flagged" % (len(errors), 100 * t_sorted[half], r_sorted[half], sum(flagged)))
    bad = [(k, e) for k, e in enumerate(errors) if e[0] > 0.1 or e[1] > 1.0]
    worst_unflagged = max((e[1] for k, e in enumerate(errors) if not flagged[k + 1]), default=0.0)
    print("bad pairs (> 10 cm or 1 deg): %d, unflagged: %d; worst unflagged rotation %.2f deg" %
          (len(bad), sum(1 for k, _ in bad if not flagged[k + 1]), worst_unflagged))
    for k, (t, r) in bad:
        print("  %d-%d: %.3f m %.2f deg%s" % (first + step * k, first + step * (k + 1), t, r, " (flagged)" if flagged[k + 1] else ""))


if __name__ == "__main__":
    main()
