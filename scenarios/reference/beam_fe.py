#!/usr/bin/env python3
"""Plane-stress finite-element reference for the split beams of dcb_2d.toml and enf_2d.toml.

Independent of Fissure (other method, other code): the 100 x 24 mm beam clamped on its left
edge, a 50 mm mid-plane crack from the right end, each arm loaded on its end face by a
uniform shear traction totalling P = 1000 N/m. Q4 elements (2 x 2 Gauss points) on a
uniform square mesh. G is the derivative of the complementary work with crack length at
fixed load, G = d(f.u/2)/da, by a central difference over one element; K = sqrt(E G).

  dcb: the arms pulled apart (mode I); crack faces free.
  enf: both arms pushed down (mode II); crack faces share their normal displacement and
       slide freely (frictionless closed contact). The contact force is identically zero
       in linear elasticity (the two arms deflect alike), so free faces give the same G.

J converges at about first order in the element size (crack-tip singularity), so the
converged value is estimated from the last three meshes by Aitken extrapolation.

Usage: python3 beam_fe.py {dcb,enf} [element sizes in mm ...]   (needs numpy and scipy)
Result, 1 / 0.5 / 0.25 / 0.125 mm:
  dcb: K_I  = 152.19, 152.67, 152.87, 152.96 kPa sqrt(m); extrapolated 153.0 (Eq. 23: 152.84)
  enf: K_II = 118.79, 119.37, 119.62, 119.74 kPa sqrt(m); extrapolated 119.8 (Eq. 24: 115.84)
"""
import sys

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

E, NU = 2.3e9, 0.33  # Pa, -
LENGTH, HEIGHT, ARM = 0.100, 0.024, 0.012  # m
CRACK = 0.050  # m, from the right end
P = 1000.0  # N per metre of thickness, on each arm


def element_stiffness(size):
    """Q4 stiffness of a square element of side `size`, plane stress, unit thickness."""
    d = E / (1 - NU**2) * np.array([[1, NU, 0], [NU, 1, 0], [0, 0, (1 - NU) / 2]])
    xi_n = np.array([-1, 1, 1, -1])
    eta_n = np.array([-1, -1, 1, 1])
    jac = size / 2
    k = np.zeros((8, 8))
    for xi in (-1 / np.sqrt(3), 1 / np.sqrt(3)):
        for eta in (-1 / np.sqrt(3), 1 / np.sqrt(3)):
            dx = xi_n * (1 + eta_n * eta) / 4 / jac
            dy = eta_n * (1 + xi_n * xi) / 4 / jac
            b = np.zeros((3, 8))
            b[0, 0::2] = dx
            b[1, 1::2] = dy
            b[2, 0::2] = dy
            b[2, 1::2] = dx
            k += b.T @ d @ b * jac * jac
    return k


def complementary_work(mode, size, x_tip):
    """f.u/2 per metre of thickness with the crack tip at x_tip (m)."""
    nx, ny = round(LENGTH / size), round(HEIGHT / size)
    row, tip = round(ARM / size), round(x_tip / size)
    node = np.arange((nx + 1) * (ny + 1)).reshape(ny + 1, nx + 1)
    # crack-row nodes right of the tip get a copy that belongs to the upper arm
    copy = {i: node.size + k for k, i in enumerate(range(tip + 1, nx + 1))}
    nodes = node.size + len(copy)
    ei, ej = (a.ravel() for a in np.meshgrid(np.arange(nx), np.arange(ny)))
    conn = np.stack([node[ej, ei], node[ej, ei + 1], node[ej + 1, ei + 1], node[ej + 1, ei]], 1)
    for corner, di in ((0, 0), (1, 1)):
        upper = (ej == row) & (ei + di > tip)
        conn[upper, corner] = [copy[i] for i in ei[upper] + di]
    ux = np.arange(nodes)
    uy = np.arange(nodes) + nodes
    if mode == "enf":
        for i, c in copy.items():
            uy[c] = uy[node[row, i]]
    dofs = np.empty((len(conn), 8), dtype=np.int64)
    dofs[:, 0::2] = ux[conn]
    dofs[:, 1::2] = uy[conn]
    rows = np.repeat(dofs, 8, axis=1).ravel()
    cols = np.tile(dofs, (1, 8)).ravel()
    vals = np.tile(element_stiffness(size).ravel(), len(conn))
    k = sp.coo_matrix((vals, (rows, cols)), shape=(2 * nodes, 2 * nodes)).tocsr()
    f = np.zeros(2 * nodes)
    for j0, j1, upper in ((0, row, False), (row, ny, True)):
        sign = 1.0 if (mode == "dcb" and upper) else -1.0
        for j in range(j0, j1):
            for jj in (j, j + 1):
                n = copy[nx] if (upper and jj == row) else node[jj, nx]
                f[uy[n]] += sign * P / (j1 - j0) / 2
    fixed = np.concatenate([ux[node[:, 0]], uy[node[:, 0]]])
    free = np.setdiff1d(np.unique(dofs), fixed)
    u = np.zeros(2 * nodes)
    u[free] = spla.spsolve(k[free][:, free].tocsc(), f[free])
    return 0.5 * f @ u


def stress_intensity(mode, size):
    """K (Pa sqrt(m)) from G = dW/da at fixed load, central difference over one element."""
    x_tip = LENGTH - CRACK
    longer = complementary_work(mode, size, x_tip - size)
    shorter = complementary_work(mode, size, x_tip + size)
    return np.sqrt(E * (longer - shorter) / (2 * size))


def main():
    mode = sys.argv[1] if len(sys.argv) > 1 else "enf"
    if mode not in ("dcb", "enf"):
        sys.exit("mode must be dcb or enf")
    sizes = [float(s) * 1e-3 for s in sys.argv[2:]] or [1e-3, 0.5e-3, 0.25e-3]
    ks = []
    for size in sizes:
        ks.append(stress_intensity(mode, size))
        print(f"{size * 1e3:g} mm: K = {ks[-1] / 1e3:.2f} kPa sqrt(m)", flush=True)
    if len(ks) >= 3:
        a, b, c = ks[-3:]
        print(f"extrapolated (Aitken): {(c - (c - b) ** 2 / ((c - b) - (b - a))) / 1e3:.2f}")


if __name__ == "__main__":
    main()
