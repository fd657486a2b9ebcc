"""Fits a measured material and plots its NDF against the GGX and Beckmann fits (docs/python.md).

Usage: python plot_ndf.py SOURCE [OUT.png]   (SOURCE: a MERL .binary, an RGL .bsdf or builtin:NAME)
"""
import sys

import matplotlib.pyplot as plt
import numpy as np

import facetfit


def ggx(theta, alpha):
    c2 = np.cos(theta) ** 2
    return alpha**2 / (np.pi * (c2 * (alpha**2 - 1.0) + 1.0) ** 2)


def beckmann(theta, alpha):
    c2 = np.cos(theta) ** 2
    return np.exp((c2 - 1.0) / (c2 * alpha**2)) / (np.pi * alpha**2 * c2**2)


def main():
    source = sys.argv[1] if len(sys.argv) > 1 else "builtin:gold-ggx-0.15"
    out = sys.argv[2] if len(sys.argv) > 2 else "ndf.png"
    fit = facetfit.fit(source)
    if not fit.ok:
        sys.exit(f"{source}: {fit.problem}")
    record = fit.record
    theta = np.linspace(0.0, np.radians(89.0), 400)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.semilogy(np.degrees(theta), fit.D(theta), label="tabulated (refined)")
    ax.semilogy(np.degrees(fit.theta), fit.ndf_extraction, ".", label="power iteration (paper)")
    ax.semilogy(np.degrees(theta), ggx(theta, record["ggx"]["alpha"]), "--", label=f"GGX fit, alpha {record['ggx']['alpha']:.3f}")
    ax.semilogy(np.degrees(theta), beckmann(theta, record["beckmann"]["alpha"]), ":",
                label=f"Beckmann fit, alpha {record['beckmann']['alpha']:.3f}")
    ax.set_xlabel("theta_h (degrees)")
    ax.set_ylabel("D (1/sr)")
    ax.set_ylim(1e-3 * fit.ndf.max(), 2.0 * fit.ndf.max())
    ax.set_title(fit.source)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    print(f"{out}: alpha_ggx {fit.alpha_ggx:.4f}, body {np.round(fit.body, 4)}, error {fit.error:.4f}")


if __name__ == "__main__":
    main()
