"""facetfit: microfacet fits of measured BRDFs, LUT textures, rendering and Delta E 2000.

Directions are unit vectors in the local frame (normal along +z, pointing away from the surface):
``o`` toward the viewer first, ``i`` toward the light second (docs/conventions.md). Arrays of
directions have shape (..., 3); one of the two may be a single vector. Errors in inputs raise
:class:`facetfit.Error` with one line naming the input. See docs/python.md.
"""
from pathlib import Path as _Path

from ._facetfit import (Error, Fit, Lut, Measurement, Model, __version__, bake, builtins, delta_e, fit, load,
                        lut_format_version, material, read_lut, render, write_image)


def shader_dir():
    """The folder of the OSL shaders shipped with this package (facetfit_material.osl, facetfit_preview.osl and
    their header facetfit.h), written for the LUTs it bakes (format ``lut_format_version``): compile these, not
    another checkout's, so that shader and LUT format never drift apart."""
    return _Path(__file__).with_name("osl")


__all__ = ["Error", "Fit", "Lut", "Measurement", "Model", "__version__", "bake", "builtins", "delta_e", "fit", "load",
           "lut_format_version", "material", "read_lut", "render", "shader_dir", "write_image"]
