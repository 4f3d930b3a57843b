#!/usr/bin/env python3
"""Groups sources into units for clang-tidy (scripts/check_tidy.sh runs this).

clang-tidy's matchers walk a file's whole syntax tree, the standard library's and nlohmann's,
CLI11's, pybind11's and OpenVDB's headers included, and then print only what the header filter
lets through: most of a file's time goes to headers that every file of its library parses again.
A unit is one generated file that includes every source of a directory compiled with the same
flags (one library, the sph program, the Python module), so that their headers are parsed and
walked once. Findings are the same, file and line: the sources are checked as headers of the
unit (.clang-tidy's HeaderFilterRegex lets their .cpp through).

Usage: tidy_units.py BUILD_DIR OUT_DIR FILE...
Writes OUT_DIR/units/*.cpp and OUT_DIR/compile_commands.json (each unit, and each source with
its own command, for checking a unit's files one by one), and prints one line per unit, the
most sources first: the unit's path and its sources, separated by tabs.
"""

import json
import os
import re
import shlex
import sys


def command_of(entry):
    """A compile database entry's command line, whichever form the entry gives it in."""
    return entry.get("command") or shlex.join(entry["arguments"])


def main():
    if len(sys.argv) < 4:
        sys.exit("usage: tidy_units.py BUILD_DIR OUT_DIR FILE...")
    build, out, files = sys.argv[1], sys.argv[2], sys.argv[3:]
    with open(os.path.join(build, "compile_commands.json")) as f:
        database = json.load(f)
    by_file = {os.path.realpath(e["file"]): e for e in database}
    # A target built with CMake's unity build (SPH_UNITY) has one entry per generated file that
    # includes its sources: each source gets that entry's command.
    for e in database:
        if os.sep + "Unity" + os.sep in e["file"]:
            command = command_of(e)
            with open(e["file"]) as f:
                for source in re.findall(r'^#include "([^"]+)"', f.read(), re.M):
                    by_file.setdefault(os.path.realpath(source),
                                       {"directory": e["directory"], "file": source,
                                        "command": command.replace(e["file"], source)})

    units = {}  # (directory, flags) -> sources, in the order given
    entries = []
    for name in files:
        path = os.path.realpath(name)
        entry = by_file.get(path)
        if entry is None:
            sys.exit(f"tidy_units: {name} is not in {build}/compile_commands.json: "
                     "a source of src/, apps/ or python/ that CMake builds is expected")
        command = command_of(entry)
        flags = re.sub(r" -o \S+", " ", command.replace(entry["file"], " "))
        key = (os.path.dirname(path), entry["directory"], flags)
        units.setdefault(key, []).append(path)
        entries.append({"directory": entry["directory"], "file": path, "command": command})

    os.makedirs(os.path.join(out, "units"), exist_ok=True)
    lines = []
    for index, ((source_dir, directory, flags), sources) in enumerate(units.items()):
        rel = os.path.relpath(source_dir).replace(os.sep, "_")
        unit = os.path.realpath(os.path.join(out, "units", f"{rel}_{index}.cpp"))
        with open(unit, "w") as f:
            for s in sources:
                f.write(f'#include "{s}"  // NOLINT(bugprone-suspicious-include)\n')
        first = by_file[sources[0]]
        command = re.sub(r" -o \S+", f" -o {unit}.o", command_of(first).replace(first["file"], unit))
        entries.append({"directory": directory, "file": unit, "command": command})
        lines.append((len(sources), unit, sources))

    with open(os.path.join(out, "compile_commands.json"), "w") as f:
        json.dump(entries, f, indent=1)
    for _, unit, sources in sorted(lines, key=lambda x: -x[0]):
        print("\t".join([unit] + sources))


if __name__ == "__main__":
    main()
