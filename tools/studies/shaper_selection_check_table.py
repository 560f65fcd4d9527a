#!/usr/bin/env python3
"""Checks that a study document is current: every non-empty line a study program prints must
appear verbatim in the document. Usage: shaper_selection_check_table.py PROGRAM DATA_DIR DOCUMENT"""
import subprocess
import sys


def main() -> int:
    program, data_dir, document = sys.argv[1:4]
    printed = subprocess.run([program, data_dir], check=True, capture_output=True, text=True).stdout
    with open(document, encoding="utf-8") as f:
        text = f.read()
    stale = [line for line in printed.splitlines() if line.strip() and line not in text]
    for line in stale:
        print(f"{document}: missing or outdated line (regenerate with {program}):\n  {line}")
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
