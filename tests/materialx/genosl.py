"""Generates OSL source from a MaterialX document with MaterialX's own OSL generator (PyPI materialx), for a
renderer that compiles OSL (Cycles' script node): OUT_DIR/NAME.osl from the document's surfacematerial,
with the generator's include files (mx_funcs.h ...) copied beside it.
Usage: python genosl.py DOC.mtlx OUT_DIR
"""
import os
import shutil
import sys

import MaterialX as mx
import MaterialX.PyMaterialXGenOsl as mx_osl
import MaterialX.PyMaterialXGenShader as mx_gen


def main(path, out_dir):
    stdlib = mx.createDocument()
    search = mx.getDefaultDataSearchPath()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), search, stdlib)
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, path)
    doc.importLibrary(stdlib)
    material = doc.getMaterialNodes()[0]
    generator = mx_osl.OslShaderGenerator.create()
    context = mx_gen.GenContext(generator)
    context.registerSourceCodeSearchPath(search)
    source = generator.generate(material.getName(), material, context).getSourceCode(mx_gen.PIXEL_STAGE)
    os.makedirs(out_dir, exist_ok=True)
    out = os.path.join(out_dir, material.getName() + ".osl")
    with open(out, "w") as f:
        f.write(source)
    include = search.find("libraries/stdlib/genosl/include")
    for header in os.listdir(include.asString()):
        shutil.copy(os.path.join(include.asString(), header), out_dir)
    print(out)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
