#!/usr/bin/env python3
"""Tabulates a neural BRDF (Sztrajman et al. 2021, ../shared/data/nbrdf/NAME.h5) into a MERL table, the accuracy
anchor that `make accuracy` renders beside facetfit's representations.

The network (layout in ../shared/data/README.md): inputs the half vector with its azimuth set to zero,
(sin theta_h, 0, cos theta_h), and the difference vector (sin theta_d cos phi_d, sin theta_d sin phi_d, cos theta_d);
two dense layers of 21 ReLU units, 3 linear outputs, then exp(x) - 1 clamped at 0: the RGB BRDF in 1/sr, no cosine.
It is evaluated at the bins' lower edges (facetfit's default `--merl-bins start`), each value the mean of the network
at phi_d and phi_d + pi (the training data repeat every pi; the mean halves the network's error), and written as
MERL's reference reader reads it: the value divided by the channel's scale (1, 1.15, 1.66) / 1500.

Usage: nbrdf_table.py NETWORK.h5 OUT.binary   (needs numpy and h5py)"""
import os
import struct
import sys

import h5py
import numpy as np

THETA_H, THETA_D, PHI_D = 90, 90, 180
SCALE = np.array([1.0, 1.15, 1.66]) / 1500.0


def layers(path):
    """The three dense layers' (kernel, bias), in order."""
    with h5py.File(path, "r") as f:
        names = [n.decode() for n in f.attrs["layer_names"] if n.decode().startswith("dense")]
        if len(names) != 3:
            sys.exit(f"{path}: expected 3 dense layers, found {len(names)}")
        return [(np.asarray(f[n][n]["kernel:0"], np.float64), np.asarray(f[n][n]["bias:0"], np.float64)) for n in names]


def evaluate(net, x):
    """The network's RGB values (1/sr) at inputs x (N x 6)."""
    (w1, b1), (w2, b2), (w3, b3) = net
    y = np.maximum(x @ w1 + b1, 0.0)
    y = np.maximum(y @ w2 + b2, 0.0)
    return np.maximum(np.expm1(y @ w3 + b3), 0.0)


def table(net):
    """The MERL table (3, THETA_H, THETA_D, PHI_D) in 1/sr at the bins' lower edges, phi_d averaged with phi_d + pi."""
    theta_h = (np.arange(THETA_H) / THETA_H) ** 2 * (np.pi / 2)
    theta_d = np.arange(THETA_D) / THETA_D * (np.pi / 2)
    out = np.zeros((THETA_H, THETA_D, PHI_D, 3))
    for shift in (0.0, np.pi):
        phi_d = np.arange(PHI_D) / PHI_D * np.pi + shift
        h, d, p = np.meshgrid(theta_h, theta_d, phi_d, indexing="ij")
        x = np.stack([np.sin(h), np.zeros_like(h), np.cos(h), np.sin(d) * np.cos(p), np.sin(d) * np.sin(p), np.cos(d)], axis=-1)
        out += 0.5 * evaluate(net, x.reshape(-1, 6)).reshape(out.shape)
    return np.moveaxis(out, -1, 0)


def write_merl(path, values):
    """MERL's layout: three int32 dimensions, then each channel's doubles, phi_d fastest; written through a temporary."""
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(struct.pack("<3i", THETA_H, THETA_D, PHI_D))
        for c in range(3):
            f.write((values[c] / SCALE[c]).astype("<f8").tobytes())
    os.replace(tmp, path)


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    values = table(layers(argv[1]))
    if not np.all(np.isfinite(values)):
        sys.exit(f"{argv[1]}: the network gives non-finite values")
    write_merl(argv[2], values)


if __name__ == "__main__":
    main(sys.argv)
