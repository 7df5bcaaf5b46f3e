#!/usr/bin/env python3
"""Injects an extrinsic shock into a simulated dataset (thesis Table 4.6).

From frame FIRST on, the LiDAR's mounting moves by Delta = SE3::exp([rho, phi])
(mlidar's tangent order [t, r]; Exp(phi), J_l(phi) rho): T_base_lidar becomes
T_base_lidar Delta, so each point p of its scans becomes Delta^-1 p (the same
shift as tests/apps/test_cli_slam.cpp's shift_mounting). The scans are binary
PCD files as `mlidar simulate drive` writes them (x y z float32 first).

  experiments/shift_mounting.py SCANS_DIR FIRST TX TY TZ RX_DEG RY_DEG RZ_DEG
prints Delta's quaternion (w x y z) and translation, to compose the new truth.
"""
import math
import os
import struct
import sys


def skew(v):
    return [[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]]


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def so3_exp(phi):
    angle = math.sqrt(sum(c * c for c in phi))
    K = skew(phi)
    K2 = matmul(K, K)
    if angle < 1e-12:
        a, b = 1.0, 0.5
    else:
        a, b = math.sin(angle) / angle, (1 - math.cos(angle)) / angle**2
    R = [[(1.0 if i == j else 0.0) + a * K[i][j] + b * K2[i][j] for j in range(3)] for i in range(3)]
    # J_l = I + (1 - cos)/a^2 K + (a - sin)/a^3 K^2
    c = (angle - math.sin(angle)) / angle**3 if angle > 1e-12 else 1.0 / 6.0
    J = [[(1.0 if i == j else 0.0) + b * K[i][j] + c * K2[i][j] for j in range(3)] for i in range(3)]
    return R, J


def quaternion(R):
    w = math.sqrt(max(0.0, 1 + R[0][0] + R[1][1] + R[2][2])) / 2
    return (w, (R[2][1] - R[1][2]) / (4 * w), (R[0][2] - R[2][0]) / (4 * w), (R[1][0] - R[0][1]) / (4 * w))


def shift_file(path, R_inv, t_inv):
    data = open(path, "rb").read()
    end = data.index(b"DATA binary\n") + len(b"DATA binary\n")
    header = data[:end].decode()
    fields = dict(line.split(" ", 1) for line in header.splitlines() if line and not line.startswith("#"))
    if fields["FIELDS"].split()[:3] != ["x", "y", "z"] or fields["TYPE"].split()[:3] != ["F", "F", "F"]:
        sys.exit(f"{path}: expected x y z float32 as the first fields")
    stride = sum(int(s) * int(c) for s, c in zip(fields["SIZE"].split(), fields["COUNT"].split()))
    points = int(fields["POINTS"])
    body = bytearray(data[end:end + points * stride])
    for i in range(points):
        x, y, z = struct.unpack_from("<fff", body, i * stride)
        p = [R_inv[r][0] * x + R_inv[r][1] * y + R_inv[r][2] * z + t_inv[r] for r in range(3)]
        struct.pack_into("<fff", body, i * stride, *p)
    tmp = path + ".tmp"
    with open(tmp, "wb") as out:
        out.write(data[:end] + bytes(body) + data[end + points * stride:])
    os.replace(tmp, path)


def main():
    if len(sys.argv) != 9:
        sys.exit(__doc__)
    folder, first = sys.argv[1], int(sys.argv[2])
    rho = [float(v) for v in sys.argv[3:6]]
    phi = [math.radians(float(v)) for v in sys.argv[6:9]]
    R, J = so3_exp(phi)
    t = [sum(J[i][k] * rho[k] for k in range(3)) for i in range(3)]
    R_inv = [[R[j][i] for j in range(3)] for i in range(3)]  # Delta^-1 = (R^T, -R^T t)
    t_inv = [-sum(R_inv[i][k] * t[k] for k in range(3)) for i in range(3)]
    for name in sorted(os.listdir(folder)):
        if name.endswith(".pcd") and int(name[:-4]) >= first:
            shift_file(os.path.join(folder, name), R_inv, t_inv)
    print(" ".join(f"{v:.12g}" for v in quaternion(R)), " ".join(f"{v:.12g}" for v in t))


if __name__ == "__main__":
    main()
