"""Rotations of the bar's frame: quaternion and matrix forms (plain Python, also compiled).

``quat_to_matrix`` writes into a given 3x3 array so the kernel (mech.kernel, which compiles
it) can call it in its loop without allocating; the Python side calls the same function.
"""

from __future__ import annotations

import math

import numpy as np


def quat_to_matrix(qw, qx, qy, qz, R):
    """Body->world rotation matrix of a (not necessarily unit) quaternion, into R."""
    s = 1.0 / (qw * qw + qx * qx + qy * qy + qz * qz)
    R[0, 0] = 1.0 - 2.0 * s * (qy * qy + qz * qz)
    R[0, 1] = 2.0 * s * (qx * qy - qz * qw)
    R[0, 2] = 2.0 * s * (qx * qz + qy * qw)
    R[1, 0] = 2.0 * s * (qx * qy + qz * qw)
    R[1, 1] = 1.0 - 2.0 * s * (qx * qx + qz * qz)
    R[1, 2] = 2.0 * s * (qy * qz - qx * qw)
    R[2, 0] = 2.0 * s * (qx * qz - qy * qw)
    R[2, 1] = 2.0 * s * (qy * qz + qx * qw)
    R[2, 2] = 1.0 - 2.0 * s * (qx * qx + qy * qy)



def rotation_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rotation_y(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def matrix_to_quaternion(R: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z) of a rotation matrix (Shepperd's method)."""
    tr = np.trace(R)
    if tr > 0:
        s = 2.0 * math.sqrt(tr + 1.0)
        q = [0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s]
    elif R[0, 0] > R[1, 1] and R[0, 0] > R[2, 2]:
        s = 2.0 * math.sqrt(1.0 + R[0, 0] - R[1, 1] - R[2, 2])
        q = [(R[2, 1] - R[1, 2]) / s, 0.25 * s, (R[0, 1] + R[1, 0]) / s, (R[0, 2] + R[2, 0]) / s]
    elif R[1, 1] > R[2, 2]:
        s = 2.0 * math.sqrt(1.0 + R[1, 1] - R[0, 0] - R[2, 2])
        q = [(R[0, 2] - R[2, 0]) / s, (R[0, 1] + R[1, 0]) / s, 0.25 * s, (R[1, 2] + R[2, 1]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + R[2, 2] - R[0, 0] - R[1, 1])
        q = [(R[1, 0] - R[0, 1]) / s, (R[0, 2] + R[2, 0]) / s, (R[1, 2] + R[2, 1]) / s, 0.25 * s]
    q = np.array(q)
    return q / np.linalg.norm(q)
