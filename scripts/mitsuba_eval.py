#!/usr/bin/env python3
"""Mitsuba 3's `measured` BSDF evaluated at direction pairs: the reference for facetfit's RGL reader.

Usage: mitsuba_eval.py FILE.bsdf PAIRS.json OUT.json
PAIRS.json: [[wi, wo], ...] in the local frame, wi Mitsuba's si.wi (the side toward the viewer), wo the
other direction. OUT.json: [[r, g, b], ...], Mitsuba's eval, which is f(wi, wo) cos(theta_wo).
"""
import json
import sys

import mitsuba as mi


def main(bsdf_file, pairs_file, out_file):
    mi.set_variant("scalar_rgb")
    bsdf = mi.load_dict({"type": "measured", "filename": bsdf_file})
    context = mi.BSDFContext()
    values = []
    for wi, wo in json.load(open(pairs_file)):
        si = mi.SurfaceInteraction3f()
        si.sh_frame = mi.Frame3f(mi.Vector3f(0.0, 0.0, 1.0))  # the local frame is the world frame
        si.wi = mi.Vector3f(*wi)
        v = bsdf.eval(context, si, mi.Vector3f(*wo))
        values.append([float(v[0]), float(v[1]), float(v[2])])
    with open(out_file, "w") as f:
        json.dump(values, f)


if __name__ == "__main__":
    main(*sys.argv[1:4])
