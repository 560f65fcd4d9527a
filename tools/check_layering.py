#!/usr/bin/env python3
"""Checks the module dependency rules of docs/design.md on #include lines.

Each module may include headers of the modules listed for it below and nothing else of ours;
`core` depends on nothing of ours. Run: python3 tools/check_layering.py [repo root]
Exit status 0 when the rules hold, 1 with one line per violation otherwise.
"""
import pathlib
import re
import sys

ALLOWED = {
    "core": set(),
    "motion": {"core"},
    "machine": {"core"},
    "rapid": {"core"},
    "frf": {"core"},
    "fit": {"core"},
    "shaping": {"core", "fit"},
    "tuning": {"core", "fit"},
    "vcnc": {"core", "motion", "machine", "rapid", "frf", "fit", "tuning"},
    "io": {"core", "motion", "machine", "rapid", "vcnc", "frf", "fit", "shaping", "tuning"},
    "report": {"core", "motion", "machine", "rapid", "vcnc", "frf", "fit", "shaping", "tuning", "io"},
}
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]servotwin/([a-z_]+)/')


def violations(root: pathlib.Path):
    for folder in ("include/servotwin", "src"):
        base = root / folder
        if not base.is_dir():
            continue
        for module_dir in sorted(p for p in base.iterdir() if p.is_dir()):
            module = module_dir.name
            allowed = ALLOWED.get(module)
            if allowed is None:
                yield f"{module_dir}: module '{module}' is not in docs/design.md's module map"
                continue
            for path in sorted(module_dir.rglob("*.[ch]pp")):
                for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
                    m = INCLUDE.match(line)
                    if m and m.group(1) != module and m.group(1) not in allowed:
                        yield f"{path}:{number}: {module} must not include servotwin/{m.group(1)}/"
                    if re.match(r'^\s*#\s*include\s*[<"](fstream|filesystem)[>"]', line) and module not in ("io", "report"):
                        yield f"{path}:{number}: {module} is an algorithm module and must not do file I/O"


def main() -> int:
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)
    found = list(violations(root))
    for v in found:
        print(v)
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
