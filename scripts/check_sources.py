#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Checks the product's files against the project's rules: no narrative of how
the project was made, every docs/design.md section that a file cites present
there, an SPDX line, and no include that names no file or points up the
layers of docs/design.md, "Layers" (check_layers.py). Lengths are warnings
that name the file, not failures: source files past about 400 lines and
functions past about 80 usually want splitting, README.md past 200 lines and
bench/RESULTS.md past 400 usually want a shorter text; a limit is never a
target to trim to.
Every C++ file of the source folders must be as clang-format (.clang-format)
writes it.
  scripts/check_sources.py [ROOT]"""
import pathlib
import re
import shutil
import subprocess
import sys

import check_layers

ROOT = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parent.parent)
SOURCE_DIRS = ["include", "src", "residuals", "solvers", "apps", "peers", "examples", "tests", "bench", "python",
               "fuzz"]
PRODUCT_DIRS = SOURCE_DIRS + ["docs", "configs", "scripts", "cmake", ".ci"]
MAX_FILE, MAX_FUNCTION, MAX_README, MAX_RESULTS = 400, 80, 200, 400
# Words that narrate the making of the project instead of describing it,
# each with one letter in a character class so that this file, which is
# checked too, does not match its own list.
PROCESS_WORDS = re.compile(
    r"\b(s[e]ssions?|spr[i]nts?|m[i]lestones?|the g[o]al|the i[s]sue|i[s]sue ?#?\d+|t[a]sk ?#?\d+|t[i]ckets?|"
    r"(first|second|third|fourth|fifth|sixth|seventh|eighth|ninth|tenth|eleventh|twelfth|\w+teenth|twentieth) "
    r"(s[e]ssion|r[o]und|p[a]ss of the work)|previously m[e]asured|used t[o] be|no l[o]nger|was b[e]fore)\b",
    re.IGNORECASE)
COMMIT_HASH = re.compile(r"\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}\b")
# A citation: docs/design.md or docs/design/<layer>.md, then one of its headings in quotes.
DESIGN_CITATION = re.compile(r'(docs/design(?:/[a-z_]+)?\.md),?\s*(?:section\s*)?\\?"([^"\\]+)\\?"')
CONTROL = re.compile(r"^\s*(if|for|while|switch|catch|do|else|try)\b|\]\s*\(|=\s*\[|return \[")


def product_files():
    files = [ROOT / "README.md", ROOT / "CMakeLists.txt", ROOT / "bench" / "RESULTS.md"]
    for folder in PRODUCT_DIRS:
        files += [p for p in (ROOT / folder).rglob("*") if p.is_file()]
    return [p for p in files if p.exists()]


def strip_code(line):
    line = re.sub(r'"(\\.|[^"\\])*"', '""', line)
    line = re.sub(r"'(\\.|[^'\\])'", "''", line)
    return line.split("//")[0]


def long_functions(path, lines):
    """Blocks opened by a function signature (not control flow, not a lambda)
    longer than MAX_FUNCTION lines."""
    found, stack, signature, parens = [], [], "", 0
    for number, raw in enumerate(lines, 1):
        code = strip_code(raw)
        if re.match(r"^\s*(namespace\b|extern \"C\")", raw) or re.match(r"^\s*}\s*//\s*namespace", raw):
            signature = ""
            continue
        for char in code:
            if char == "{" and parens > 0:  # a braced initialiser inside a signature or a for
                stack.append((number, False, ""))
                signature += char
            elif char == "}" and parens > 0:
                if stack:
                    stack.pop()
                signature += char
            elif char == "{":
                is_function = ")" in signature and not CONTROL.search(signature) and \
                    not re.search(r"\b(struct|class|enum|union)\b", signature)
                stack.append((number, is_function, signature.strip()))
                signature, parens = "", 0
            elif char == "}":
                if stack:
                    start, is_function, name = stack.pop()
                    if is_function and number - start + 1 > MAX_FUNCTION:
                        found.append(f"{path}:{start}: function of {number - start + 1} lines (about "
                                     f"{MAX_FUNCTION} usually want splitting): {name[:70]}")
                signature = ""
            elif char == ";" and parens == 0:
                signature = ""
            else:
                parens += (char == "(") - (char == ")")
                signature += char
        signature += " "
    return found


def unformatted(files):
    """The C++ files clang-format would change, as problems (one run over all of them)."""
    tool = shutil.which("clang-format")
    if tool is None:
        return ["clang-format not found (scripts/deps.sh installs it)"]
    result = subprocess.run([tool, "--dry-run", "--Werror"] + [str(f) for f in files], capture_output=True, text=True)
    changed = sorted({line.split(":", 1)[0] for line in result.stderr.splitlines() if ": error: code should be" in line})
    return [f"{pathlib.Path(f).resolve().relative_to(ROOT.resolve())}: not as clang-format writes it "
            "(clang-format -i)" for f in changed]


def main():
    problems, warnings = [], []
    headings = {}  # design file -> its headings
    for design in [ROOT / "docs" / "design.md"] + sorted((ROOT / "docs" / "design").glob("*.md")):
        headings[design.relative_to(ROOT).as_posix()] = {
            h.strip() for h in re.findall(r"^#+\s*(?:\d+(?:\.\d+)*\.?\s*)?(.+)$", design.read_text(), re.M)}
    for path in product_files():
        relative = path.relative_to(ROOT)
        try:
            text = path.read_text()
        except UnicodeDecodeError:
            continue
        lines = text.split("\n")
        # Citations may wrap over comment lines.
        joined = re.sub(r"\n\s*(//|#)\s*", " ", text)
        for cited, section in DESIGN_CITATION.findall(joined):
            section = " ".join(section.split())
            if section not in headings.get(cited, set()):
                problems.append(f"{relative}: {cited} has no section \"{section}\"")
        is_source = path.suffix in {".cpp", ".hpp", ".h", ".cc"}
        if is_source and len(lines) - 1 > MAX_FILE:
            warnings.append(f"{relative}: {len(lines) - 1} lines (about {MAX_FILE} usually want splitting)")
        if is_source:
            warnings += long_functions(relative, lines)
        if (is_source or path.suffix in {".sh", ".py", ".cmake"} or path.name == "CMakeLists.txt") and \
                "SPDX-License-Identifier:" not in "\n".join(lines[:3]):
            problems.append(f"{relative}: no SPDX-License-Identifier line")
        for number, line in enumerate(lines, 1):
            match = PROCESS_WORDS.search(line)
            if match:
                problems.append(f"{relative}:{number}: narrates the work ('{match.group(0)}')")
            if path.suffix == ".md" and COMMIT_HASH.search(line):
                problems.append(f"{relative}:{number}: commit hash '{COMMIT_HASH.search(line).group(0)}'")
            if re.search(r"(?<!docs/)\bDESIG[N]\.md", line):
                problems.append(f"{relative}:{number}: cites a design file outside the repository")
    for name, limit in (("README.md", MAX_README), ("bench/RESULTS.md", MAX_RESULTS)):
        count = len((ROOT / name).read_text().split("\n")) - 1
        if count > limit:
            warnings.append(f"{name}: {count} lines (about {limit} is what a reader takes in)")
    problems += check_layers.problems(ROOT.resolve())
    problems += unformatted([p for folder in SOURCE_DIRS for p in (ROOT / folder).rglob("*")
                             if p.suffix in {".cpp", ".hpp"} and "data" not in p.relative_to(ROOT).parts])
    for warning in warnings:
        print("warning:", warning)
    for problem in problems:
        print(problem)
    print(f"check_sources: {len(problems)} problems, {len(warnings)} warnings")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
