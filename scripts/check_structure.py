#!/usr/bin/env python3
"""Structure limits of docs/architecture.md, checked on our code (tests excluded):

- includes point inward only: each runtime/ folder includes only the runtime
  folders its CMake target links (runtime/*/CMakeLists.txt, DEPENDS, followed
  transitively), and each top-level folder only the folders below it;
- no function longer than 120 lines (extents from Universal Ctags);
- no folder with more than 30 source files.

Prints every offence and exits 1 if there is one."""
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CODE_DIRS = ["runtime", "retarget", "graph_builder", "input", "firmware_sim", "render_es", "character", "app"]
# What each top-level folder may include (its own folder besides): the link
# graph of the top-level CMakeLists.txt, written out.
TOP_LEVEL_ALLOWED = {
    "runtime": set(),
    "retarget": {"runtime"},
    "graph_builder": {"runtime", "retarget"},
    "input": {"runtime"},
    "render_es": {"runtime"},
    "firmware_sim": {"runtime", "input"},
    "character": {"runtime", "retarget", "render_es"},
    "app": {"runtime", "retarget", "graph_builder", "input", "firmware_sim", "render_es", "character"},
}
MAX_FUNCTION_LINES = 120
MAX_FOLDER_FILES = 30
SOURCE_EXT = (".cpp", ".hpp", ".h", ".c")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def source_files(top):
    for folder, _, names in os.walk(os.path.join(ROOT, top)):
        for name in sorted(names):
            if name.endswith(SOURCE_EXT):
                yield os.path.join(folder, name)


def runtime_allowed():
    """runtime folder -> set of runtime folders it may include (itself too)."""
    direct = {}
    runtime = os.path.join(ROOT, "runtime")
    for name in sorted(os.listdir(runtime)):
        cmake = os.path.join(runtime, name, "CMakeLists.txt")
        if not os.path.isfile(cmake):
            continue
        text = open(cmake, encoding="utf-8").read()
        deps = set()
        for block in re.findall(r"DEPENDS([^)]*?)(?:PRIVATE_DEPENDS|SOURCES|\))", text):
            deps |= {d[len("marionette_"):] for d in block.split() if d.startswith("marionette_")}
        direct[name] = deps - {"options"}
    closure = {}
    for name in direct:
        seen, todo = {name}, [name]
        while todo:
            for d in direct.get(todo.pop(), ()):
                if d not in seen:
                    seen.add(d)
                    todo.append(d)
        closure[name] = seen
    return closure


def check_includes(problems):
    allowed_runtime = runtime_allowed()
    for top in CODE_DIRS:
        for path in source_files(top):
            rel = os.path.relpath(path, ROOT)
            parts = rel.split(os.sep)
            for number, line in enumerate(open(path, encoding="utf-8"), 1):
                m = INCLUDE.match(line)
                if not m:
                    continue
                target = m.group(1).split("/")
                if len(target) < 2:
                    continue
                if target[0] != top and target[0] not in TOP_LEVEL_ALLOWED[top]:
                    problems.append(f"{rel}:{number}: {top}/ may not include {m.group(1)}")
                elif top == "runtime" == target[0] and len(parts) > 2 and len(target) > 2:
                    if target[1] not in allowed_runtime.get(parts[1], {parts[1]}):
                        problems.append(f"{rel}:{number}: runtime/{parts[1]} does not link "
                                        f"marionette_{target[1]}, so may not include {m.group(1)}")


def check_function_lengths(problems):
    try:
        out = subprocess.run(
            ["ctags", "-R", "--languages=C++", "--kinds-C++=f", "--fields=+ne", "-x",
             "--_xformat=%{line} %{end} %{input} %{name}"] + CODE_DIRS,
            cwd=ROOT, check=True, capture_output=True, text=True).stdout
    except (OSError, subprocess.CalledProcessError) as e:
        problems.append(f"cannot run Universal Ctags for function lengths: {e}")
        return
    for row in out.splitlines():
        fields = row.split()
        if len(fields) < 4 or not fields[1].isdigit():
            continue
        lines = int(fields[1]) - int(fields[0]) + 1
        if lines > MAX_FUNCTION_LINES:
            problems.append(f"{fields[2]}:{fields[0]}: {fields[3]} is {lines} lines (limit {MAX_FUNCTION_LINES})")


def check_folder_sizes(problems):
    for top in CODE_DIRS:
        for folder, _, names in os.walk(os.path.join(ROOT, top)):
            count = sum(1 for n in names if n.endswith(SOURCE_EXT))
            if count > MAX_FOLDER_FILES:
                problems.append(f"{os.path.relpath(folder, ROOT)} holds {count} source files (limit {MAX_FOLDER_FILES})")


def main():
    problems = []
    check_includes(problems)
    check_function_lengths(problems)
    check_folder_sizes(problems)
    for p in problems:
        print(p)
    if problems:
        print(f"check_structure: {len(problems)} problem(s)")
        return 1
    print(f"check_structure: includes point inward, every function <= {MAX_FUNCTION_LINES} lines, "
          f"every folder <= {MAX_FOLDER_FILES} source files")
    return 0


if __name__ == "__main__":
    sys.exit(main())
