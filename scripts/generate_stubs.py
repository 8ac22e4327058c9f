#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Writes the type stubs of radargauss._radargauss from the built module:
the signatures pybind11 records, with **options expanded into the keywords
of option_fields(). Run against the build tree's package:
  PYTHONPATH=build/release/python scripts/generate_stubs.py > python/radargauss/_radargauss.pyi"""
import re
import sys

import radargauss._radargauss as module

OPTIONS_OF = {"match": "match", "RadarOdometry.__init__": "odometry"}
PY_TYPES = {"float": "float", "int": "int", "bool": "bool", "list of float": "list[float]",
            "sequence of 3 float": "Sequence[float]", "array (4, 4) or (7,)": "ArrayLike"}


def clean(signature):
    signature = signature.replace("radargauss._radargauss.", "")
    signature = re.sub(r"numpy\.ndarray\[[^\]]*\]", "numpy.ndarray", signature)
    signature = re.sub(r"\b(handle|object)\b", "Any", signature)
    signature = re.sub(r"\bList\[", "list[", signature)
    signature = re.sub(r"\bDict\[", "dict[", signature)
    return signature


def keywords(kind):
    """The keyword-only parameters of an options table."""
    out = []
    for field in module.option_fields(kind):
        kind_of = "str" if field["type"].startswith("{") else PY_TYPES[field["type"]]
        default = "..." if field["type"].startswith("array") else repr(field["default"])
        out.append(f"{field['keyword']}: {kind_of} = {default}")
    return out


def summary(doc):
    lines = [line.strip() for line in doc.splitlines()[1:] if line.strip()]
    return lines[0].replace('"""', "'") if lines else ""


def function_stub(qualified, function, indent):
    doc = function.__doc__ or ""
    first = doc.splitlines()[0] if doc else f"{function.__name__}(*args, **kwargs) -> Any"
    signature = clean(first)
    if not signature.startswith(function.__name__ + "("):
        return ""  # no signature of its own (object's __init__)
    if qualified in OPTIONS_OF:  # one keyword per line
        separator = ",\n" + indent + "    "
        signature = signature.replace("**kwargs", "*" + separator + separator.join(keywords(OPTIONS_OF[qualified])))
    stub = f"{indent}def {signature}:\n"
    text = summary(doc)
    return stub + (f'{indent}    """{text}"""\n' if text else f"{indent}    ...\n")


def class_stub(name, cls):
    out = [f"class {name}:\n", f'    """{(cls.__doc__ or "").splitlines()[0] if cls.__doc__ else ""}"""\n']
    for attribute, value in sorted(vars(cls).items()):
        if attribute.startswith("_") and attribute not in ("__init__", "__len__", "__repr__"):
            continue
        if isinstance(value, property):
            out.append(f"    @property\n    def {attribute}(self) -> Any: ...\n")
        elif callable(value) and hasattr(value, "__doc__"):
            out.append(function_stub(f"{name}.{attribute}", value, "    "))
    return "".join(out)


def main():
    parts = ["# SPDX-License-Identifier: BSD-3-Clause\n",
             "# Type stubs of radargauss._radargauss, written by scripts/generate_stubs.py.\n",
             "from typing import Any, Sequence\n\nimport numpy\nfrom numpy.typing import ArrayLike\n\n"]
    for name, value in sorted(vars(module).items()):
        if name.startswith("_"):
            continue
        if isinstance(value, type) and issubclass(value, Exception):
            parts.append(f"class {name}(ValueError): ...\n\n")
        elif isinstance(value, type):
            parts.append(class_stub(name, value) + "\n")
        elif callable(value):
            parts.append(function_stub(name, value, "") + "\n")
    sys.stdout.write("".join(parts).rstrip("\n") + "\n")


if __name__ == "__main__":
    main()
