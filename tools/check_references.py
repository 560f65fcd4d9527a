#!/usr/bin/env python3
"""Checks that every dissertation code cited in the sources (C7.3, E26, A6, ...: the catalog's
capabilities, examples and applications) is listed in docs/references.md, so a reader can resolve
each one to the dissertation's section and equation (issue 28 §6). Usage: check_references.py ROOT"""
import pathlib
import re
import sys

CODE = re.compile(r"\b(C[1-9](?:\.\d+[a-z]?)?|E\d{1,2}[a-z]?|A[1-6])\b")
FOLDERS = ("src", "include", "apps", "tests", "bench", "tools", "fuzz", "examples", "python")
SUFFIXES = {".cpp", ".hpp", ".py", ".h"}


def listed_codes(references):
    """Codes in the first column of the tables of docs/references.md, plus the chapter codes."""
    codes = {f"C{n}" for n in range(1, 10)}
    for line in references.read_text(encoding="utf-8").splitlines():
        m = re.match(r"^\| (\S+) \|", line)
        if m:
            codes.add(m.group(1))
    text = references.read_text(encoding="utf-8")
    codes.update(re.findall(r"\b(E\d+[a-z])\b", text))  # sub-examples named in the prose
    return codes


def main():
    root = pathlib.Path(sys.argv[1]).resolve()
    listed = listed_codes(root / "docs" / "references.md")
    missing = {}
    for folder in FOLDERS:
        for path in sorted((root / folder).rglob("*")):
            if path.suffix not in SUFFIXES or not path.is_file() or "tools/check_references.py" in str(path):
                continue
            for number, line in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
                for code in CODE.findall(line):
                    if code not in listed:
                        missing.setdefault(code, f"{path.relative_to(root)}:{number}")
    for code, where in sorted(missing.items()):
        print(f"{where}: {code} is not in docs/references.md")
    print(f"{len(listed)} codes listed, {len(missing)} cited but not listed")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
