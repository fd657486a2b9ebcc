"""facetfit: microfacet fits of measured BRDFs, LUT textures, rendering and Delta E 2000.

Directions are unit vectors in the local frame (normal along +z, pointing away from the surface):
``o`` toward the viewer first, ``i`` toward the light second (docs/conventions.md). Arrays of
directions have shape (..., 3); one of the two may be a single vector. Errors in inputs raise
:class:`facetfit.Error` with one line naming the input. See docs/python.md.
"""
from ._facetfit import (Error, Fit, Lut, Measurement, Model, __version__, bake, builtins, delta_e, fit, load,
                        material, read_lut, render, write_image)

__all__ = ["Error", "Fit", "Lut", "Measurement", "Model", "__version__", "bake", "builtins", "delta_e", "fit", "load",
           "material", "read_lut", "render", "write_image"]
