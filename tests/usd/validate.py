"""Checks USD files written by `facetfit export --usd` with PyPI's usd-core, as a look-development stage would
use them: the stage opens; its default prim is a UsdShade Material whose universal surface is the
UsdPreviewSurface fallback; a sphere of another stage binds it; the MaterialX reference's asset resolves to a
document that holds the material it names; and every validator usd-core registers passes. usd-core's wheel has
no MaterialX file format (usdMtlx): there, and only there, the reference's one composition error, "Cannot
determine file format" for the .mtlx, is expected and said. Prints one line per file; exits 1 if any fails.
Usage: python validate.py FILE.usda...
"""
import os
import sys

import MaterialX as mx
from pxr import Ar, Sdf, Usd, UsdGeom, UsdShade, UsdValidation


def problems(path):
    stage = Usd.Stage.Open(path)
    prim = stage.GetDefaultPrim()
    if not prim or not prim.IsA(UsdShade.Material):
        return ["the default prim is not a Material"]
    found = []
    material = UsdShade.Material(prim)
    source = material.ComputeSurfaceSource()[0]
    if not source or source.GetIdAttr().Get() != "UsdPreviewSurface":
        found.append("its surface is not a UsdPreviewSurface")
    # Bound in another stage, as a shot binds a look.
    shot = Usd.Stage.CreateInMemory()
    sphere = UsdGeom.Sphere.Define(shot, "/World/ball")
    look = shot.DefinePrim("/World/look")
    look.GetReferences().AddReference(os.path.abspath(path))
    UsdShade.MaterialBindingAPI.Apply(sphere.GetPrim()).Bind(UsdShade.Material(look))
    bound = UsdShade.MaterialBindingAPI(sphere.GetPrim()).ComputeBoundMaterial()[0]
    if not bound or bound.GetPath() != look.GetPath():
        found.append("a sphere does not bind it")
    # The MaterialX reference: its asset resolves, and the document holds the material it points at.
    refs = prim.GetMetadata("references")
    items = (refs.prependedItems or []) + (refs.explicitItems or []) if refs else []
    mtlx = [r for r in items if r.assetPath.endswith(".mtlx")]
    if len(mtlx) != 1:
        return found + ["no one reference to a MaterialX document"]
    anchored = Sdf.ComputeAssetPathRelativeToLayer(stage.GetRootLayer(), mtlx[0].assetPath)
    resolved = Ar.GetResolver().Resolve(anchored)
    if not resolved:
        return found + [f"the reference {mtlx[0].assetPath} does not resolve"]
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(resolved))
    name = mtlx[0].primPath.name
    if str(mtlx[0].primPath.GetParentPath()) != "/MaterialX/Materials" or not doc.getChild(name):
        found.append(f"the reference's prim {mtlx[0].primPath} is not a material of {resolved}")
    has_mtlx_format = Sdf.FileFormat.FindByExtension("mtlx") is not None
    for error in UsdValidation.ValidationContext(UsdValidation.ValidationRegistry().GetOrLoadAllValidators()).Validate(stage):
        expected = (not has_mtlx_format and error.GetName() == "CompositionError"
                    and "Cannot determine file format" in error.GetMessage() and ".mtlx" in error.GetMessage())
        if not expected:
            found.append(f"{error.GetName()}: {error.GetMessage()}")
    return found


def main(paths):
    failed = 0
    plugin = "with" if Sdf.FileFormat.FindByExtension("mtlx") else "without (its .mtlx composition error expected)"
    for path in paths:
        found = problems(path)
        print(f"{path}: {'valid' if not found else 'INVALID: ' + '; '.join(found)} (usd-core {Usd.GetVersion()}, {plugin} usdMtlx)")
        failed += bool(found)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
