"""Validates MaterialX documents with MaterialX's own library (PyPI materialx): each against the standard
data libraries, as a renderer loading it would. Prints one line per document; exits 1 if any is invalid.
Usage: python validate.py DOC.mtlx...
"""
import sys

import MaterialX as mx


def main(paths):
    stdlib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), stdlib)
    failed = 0
    for path in paths:
        doc = mx.createDocument()
        mx.readFromXmlFile(doc, path)
        doc.importLibrary(stdlib)
        valid, message = doc.validate()
        materials = [m.getName() for m in doc.getMaterialNodes()]
        print(f"{path}: {'valid' if valid and materials else 'INVALID'} (MaterialX {mx.getVersionString()}, materials {materials})"
              + ("" if valid else f": {message.strip()}"))
        failed += not (valid and materials)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
