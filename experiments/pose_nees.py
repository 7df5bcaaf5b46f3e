#!/usr/bin/env python3
"""NEES of a run's pose covariances against a ground-truth trajectory (issue 19).

usage: pose_nees.py GT.tum RUN [--every N]

RUN holds trajectory.tum and pose_covariance.txt (`mlidar odometry` or `mlidar slam`). The
estimate is aligned to the truth at its first pose (T_gt_0 T_est_0^-1), as the
covariance is zero there and grows along the run. For each later frame paired by stamp,
the error in pose_covariance.txt's tangent [t additive, r local] is
e = [t_gt - t_est, Log(R_est^T R_gt)], and NEES = e^T C^-1 e (6 dof; 3 dof for the
translation block alone). Prints the share of frames inside the chi^2 95 % band
(6 dof: [1.237, 14.449]; 3 dof: [0.216, 9.348]), below it (covariance too large),
above it (too small), and the median NEES. Standard library only.
"""
import math
import sys


def quat_to_rot(qx, qy, qz, qw):
    n = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
    x, y, z, w = qx / n, qy / n, qz / n, qw / n
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(len(b))) for j in range(len(b[0]))] for i in range(len(a))]


def transpose(a):
    return [list(r) for r in zip(*a)]


def apply(r, v):
    return [sum(r[i][k] * v[k] for k in range(3)) for i in range(3)]


def so3_log(r):
    c = max(-1.0, min(1.0, (r[0][0] + r[1][1] + r[2][2] - 1) / 2))
    angle = math.acos(c)
    v = [r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1]]
    s = 0.5 if angle < 1e-9 else angle / (2 * math.sin(angle))
    return [s * x for x in v]


def read_tum(path):
    poses = {}
    for line in open(path):
        f = line.split()
        if not f or f[0].startswith('#'):
            continue
        v = [float(x) for x in f]
        poses[round(v[0], 6)] = (quat_to_rot(*v[4:8]), v[1:4])
    return poses


def read_covariances(path):
    out = []
    for line in open(path):
        f = line.split()
        if not f or f[0].startswith('#'):
            continue
        v = [float(x) for x in f]
        c = [[0.0] * 6 for _ in range(6)]
        k = 1
        for i in range(6):
            for j in range(i, 6):
                c[i][j] = c[j][i] = v[k]
                k += 1
        out.append((round(v[0], 6), c))
    return out


def solve(a, b):
    n = len(b)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for col in range(n):
        pivot = max(range(col, n), key=lambda r: abs(m[r][col]))
        m[col], m[pivot] = m[pivot], m[col]
        if abs(m[col][col]) < 1e-300:
            return None
        for r in range(n):
            if r != col:
                f = m[r][col] / m[col][col]
                m[r] = [x - f * y for x, y in zip(m[r], m[col])]
    return [m[i][n] / m[i][i] for i in range(n)]


def main():
    gt, run = sys.argv[1], sys.argv[2]
    every = int(sys.argv[4]) if len(sys.argv) > 4 and sys.argv[3] == '--every' else 1
    truth = read_tum(gt)
    est = read_tum(run + '/trajectory.tum')
    covs = read_covariances(run + '/pose_covariance.txt')
    stamps = [s for s, _ in covs if s in truth and s in est]
    first = stamps[0]
    rg0, tg0 = truth[first]
    re0, te0 = est[first]
    r_align = matmul(rg0, transpose(re0))
    t_align = [a - b for a, b in zip(tg0, apply(r_align, te0))]
    nees6, nees3 = [], []
    cov_of = dict(covs)
    for s in stamps[1::every]:
        re, te = est[s]
        rg, tg = truth[s]
        r_est = matmul(r_align, re)
        t_est = [a + b for a, b in zip(apply(r_align, te), t_align)]
        e = [g - x for g, x in zip(tg, t_est)] + so3_log(matmul(transpose(r_est), rg))
        c = cov_of[s]
        x = solve(c, e)
        if x is not None:
            nees6.append(sum(a * b for a, b in zip(e, x)))
        x3 = solve([row[:3] for row in c[:3]], e[:3])
        if x3 is not None:
            nees3.append(sum(a * b for a, b in zip(e[:3], x3)))
    for name, values, lo, hi in (('6 dof', nees6, 1.237, 14.449), ('translation 3 dof', nees3, 0.216, 9.348)):
        values.sort()
        n = len(values)
        inside = sum(lo <= v <= hi for v in values)
        below = sum(v < lo for v in values)
        print(f'{name}: {n} frames, inside {100 * inside / n:.1f} %, below {100 * below / n:.1f} %, '
              f'above {100 * (n - inside - below) / n:.1f} %, median NEES {values[n // 2]:.3g}')


if __name__ == '__main__':
    main()
