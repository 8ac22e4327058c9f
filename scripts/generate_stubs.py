#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Writes the type stubs of radargauss._radargauss from the built module:
the signatures pybind11 records, with **options typed by one TypedDict per
option table (option_fields(kind)), each holding what the table it extends
lacks. Run against the build tree's package:
  PYTHONPATH=build/release/python scripts/generate_stubs.py > python/radargauss/_radargauss.pyi"""
import re
import sys

import radargauss._radargauss as module

# The options of each function, and the option tables as TypedDicts, each
# extending the one whose keywords it holds too.
OPTIONS_OF = {"match": "MatchOptions", "match_options": "MatchOptions", "RadarOdometry.__init__": "OdometryOptions",
              "odometry_options": "OdometryOptions", "RadarSlam.__init__": "SlamOptions", "slam_options": "SlamOptions",
              "Relocalizer.__init__": "RelocalizationOptions", "relocalization_options": "RelocalizationOptions"}
# (name, option_fields kind, the TypedDicts it extends); PlaceSearchOptions
# holds what SLAM and relocalisation share beyond the odometry's options.
TABLES = [("MatchOptions", "match", []), ("OdometryOptions", "odometry", ["MatchOptions"]),
          ("PlaceSearchOptions", None, []),
          ("SlamOptions", "slam", ["OdometryOptions", "PlaceSearchOptions"]),
          ("RelocalizationOptions", "relocalization", ["OdometryOptions", "PlaceSearchOptions"])]
PY_TYPES = {"float": "float", "int": "int", "bool": "bool", "list of float": "list[float]",
            "sequence of 3 float": "Sequence[float]", "array (4, 4) or (7,)": "ArrayLike"}


def clean(signature):
    signature = signature.replace("radargauss._radargauss.", "")
    signature = re.sub(r"numpy\.ndarray\[[^\]]*\]", "numpy.ndarray", signature)
    signature = re.sub(r"\b(handle|object)\b", "Any", signature)
    signature = re.sub(r"\bList\[", "list[", signature)
    signature = re.sub(r"\bDict\[", "dict[", signature)
    return signature


def place_search_fields():
    """The fields of SLAM and relocalisation both, beyond the odometry's."""
    odometry = {field["keyword"] for field in module.option_fields("odometry")}
    relocalization = {field["keyword"] for field in module.option_fields("relocalization")}
    return [field for field in module.option_fields("slam")
            if field["keyword"] in relocalization and field["keyword"] not in odometry]


def typed_dicts():
    """A TypedDict per option table: its keywords those it extends lack, each with its default."""
    out, keywords_of = [], {}
    for name, kind, bases in TABLES:
        fields = module.option_fields(kind) if kind else place_search_fields()
        keywords_of[name] = {field["keyword"] for field in fields}
        inherited = set().union(*(keywords_of[base] for base in bases)) if bases else set()
        doc = f'option_fields("{kind}")' if kind else "what RadarSlam and Relocalizer share beyond RadarOdometry's"
        lines = [f"class {name}({', '.join(bases) or 'TypedDict'}, total=False):\n", f'    """{doc}"""\n']
        for field in fields:
            if field["keyword"] in inherited:
                continue
            kind_of = "str" if field["type"].startswith("{") else PY_TYPES[field["type"]]
            default = "identity" if field["type"].startswith("array") else repr(field["default"])
            lines.append(f"    {field['keyword']}: {kind_of}  # {default}\n")
        out.append("".join(lines) + "\n")
    return "".join(out)


def summary(doc):
    lines = [line.strip() for line in doc.splitlines()[1:] if line.strip()]
    return lines[0].replace('"""', "'") if lines else ""


def function_stub(qualified, function, indent):
    doc = function.__doc__ or ""
    first = doc.splitlines()[0] if doc else f"{function.__name__}(*args, **kwargs) -> Any"
    signature = clean(first)
    if not signature.startswith(function.__name__ + "("):
        return ""  # no signature of its own (object's __init__)
    if qualified in OPTIONS_OF:
        signature = signature.replace("**kwargs", f"**options: Unpack[{OPTIONS_OF[qualified]}]")
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
             "from typing import Any, Sequence, TypedDict, Unpack\n\nimport numpy\nfrom numpy.typing import ArrayLike\n\n",
             typed_dicts()]
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
