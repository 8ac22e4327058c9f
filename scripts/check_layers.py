#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Checks that every quoted include names a file of the tree (beside the
includer or under include/) and that no file includes a header of a layer
above its own, with the layers read from the table of docs/design.md, "Layers".
  scripts/check_layers.py [ROOT]"""
import pathlib
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
ROW = re.compile(r"^\|\s*([a-z ]+?)\s*\|\s*((?:`[a-z_]+`,?\s*)+)\|", re.M)
# The sources mirror the headers: src/X.cpp belongs with include/radargauss/X.hpp.
LIBRARY_DIRS = ("include/radargauss", "src")
# Headers of the peers built outside CMake against their own trees (bench/*_peer.cpp).
EXTERNAL = ("kiss_icp/", "small_gicp/")


def read_layers(root):
    """[(layer, [names])] in order, from the design's table."""
    text = (root / "docs" / "design.md").read_text()
    body = text.split("## Layers", 1)[1].split("\n## ", 1)[0]
    return [(layer, re.findall(r"`([a-z_]+)`", names)) for layer, names in ROW.findall(body)]


def layer_of(name, layers):
    """The index of the layer of `name` (a path under radargauss/ without its
    suffix, e.g. map/builder), or None."""
    for index, (_, names) in enumerate(layers):
        if any(name == n or name.startswith(n + "/") for n in names):
            return index
    return None


def library_name(root, path):
    """The radargauss/ name of a file of the library, or its top folder."""
    relative = path.relative_to(root).with_suffix("").as_posix()
    for folder in LIBRARY_DIRS:
        if relative.startswith(folder + "/"):
            return relative[len(folder) + 1:]
    return relative.split("/")[0]


def included_name(root, path, target):
    if target.startswith("radargauss/"):
        return str(pathlib.PurePosixPath(target[len("radargauss/"):]).with_suffix(""))
    return library_name(root, (path.parent / target).resolve())  # a private header beside the file


def problems(root):
    layers = read_layers(root)
    found = []
    folders = [root / f for f in ["include", "src", "apps", "python", "bench", "tests", "examples", "fuzz"]]
    for path in sorted(p for folder in folders if folder.exists() for p in folder.rglob("*")
                       if p.suffix in {".hpp", ".cpp", ".h"}):
        own = layer_of(library_name(root, path), layers)
        relative = path.relative_to(root)
        if own is None:
            found.append(f"{relative}: in no layer of docs/design.md, \"Layers\"")
            continue
        for target in INCLUDE.findall(path.read_text()):
            # Every quoted include names a file: beside the includer, under
            # include/, or under the includer's top folder (tests/support/...).
            if not target.startswith(EXTERNAL) and not (path.parent / target).exists() and \
                    not (root / "include" / target).exists() and not (root / relative.parts[0] / target).exists():
                found.append(f"{relative}: includes {target}, which names no file of the tree")
                continue
            other = layer_of(included_name(root, path, target), layers)
            if other is None:
                found.append(f"{relative}: includes {target}, in no layer")
            elif other > own:
                found.append(f"{relative}: includes {target} of layer '{layers[other][0]}' above its own "
                             f"'{layers[own][0]}'")
    return found


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parent.parent).resolve()
    found = problems(root)
    for problem in found:
        print(problem)
    print(f"check_layers: {len(found)} problems")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
