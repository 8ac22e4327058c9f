#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""docs/cli.md against the tool's --help: every block that follows a marker
`<!-- help: SUBCOMMAND -->` must be that subcommand's --help-all output (the
tool's path shown as `radargauss`), and every subcommand must have one.
  scripts/cli_doc.py TOOL DOC            check (exit 1 on a difference)
  scripts/cli_doc.py TOOL DOC --update   rewrite the blocks"""
import re
import subprocess
import sys

MARKER = re.compile(r"<!-- help: ([\w-]*) -->\n```text\n(.*?)```\n", re.S)


def help_text(tool, subcommand):
    command = [tool] + ([subcommand] if subcommand != "radargauss" else []) + ["--help-all"]
    output = subprocess.run(command, capture_output=True, text=True, check=True).stdout
    return output.replace(tool, "radargauss")


def subcommands(tool):
    text = help_text(tool, "radargauss")
    listed = text.split("Subcommands:\n", 1)[1] if "Subcommands:\n" in text else ""
    return ["radargauss"] + [line.split()[0] for line in listed.splitlines() if line.strip()]


def main():
    tool, doc = sys.argv[1], sys.argv[2]
    update = "--update" in sys.argv[3:]
    text = open(doc).read()
    documented = {name for name, _ in MARKER.findall(text)}
    problems = [f"{name}: no help block in {doc}" for name in subcommands(tool) if name not in documented]

    def replace(match):
        name, block = match.group(1), match.group(2)
        current = help_text(tool, name)
        if current != block:
            problems.append(f"{name}: {doc} differs from `radargauss {name} --help-all`")
        return f"<!-- help: {name} -->\n```text\n{current}```\n"

    updated = MARKER.sub(replace, text)
    if update:
        open(doc, "w").write(updated)
        print(f"cli_doc: {doc} updated")
        return 0
    for problem in problems:
        print(problem)
    print(f"cli_doc: {len(documented)} help blocks, {len(problems)} problems"
          + ("; run scripts/cli_doc.py TOOL docs/cli.md --update" if problems else ""))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
