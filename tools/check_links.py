#!/usr/bin/env python3
"""Checks that every relative link in the README, CHANGELOG and docs/*.md resolves: a file or
folder link to an existing path, an anchor (#section, or file.md#section) to a heading of that
file (GitHub's anchors: lower case, punctuation dropped, spaces as dashes). Issue 28 §1: the README
linked a docs/peers.md that did not exist. Usage: check_links.py REPOSITORY_ROOT"""
import pathlib
import re
import sys

LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^(```|~~~)")


def anchors(path):
    """GitHub anchors of the headings of a Markdown file."""
    found = set()
    in_code = False
    for line in path.read_text(encoding="utf-8").splitlines():
        if FENCE.match(line):
            in_code = not in_code
            continue
        if in_code or not line.startswith("#"):
            continue
        title = line.lstrip("#").strip().lower()
        slug = re.sub(r"[^\w\- ]", "", title).replace(" ", "-")
        found.add(slug)
    return found


def links(path):
    """(line number, target) of every Markdown link outside code blocks."""
    in_code = False
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if FENCE.match(line):
            in_code = not in_code
            continue
        if in_code:
            continue
        for target in LINK.findall(line):
            yield number, target


def main():
    root = pathlib.Path(sys.argv[1]).resolve()
    files = [root / "README.md", root / "CHANGELOG.md"] + sorted((root / "docs").glob("*.md"))
    problems = []
    for md in files:
        for number, target in links(md):
            if re.match(r"^[a-z]+:", target):  # http:, https:, mailto:
                continue
            file_part, _, anchor = target.partition("#")
            destination = (md.parent / file_part).resolve() if file_part else md
            where = f"{md.relative_to(root)}:{number}"
            if not destination.exists():
                problems.append(f"{where}: '{target}' does not exist")
            elif anchor and destination.suffix == ".md" and anchor not in anchors(destination):
                problems.append(f"{where}: '{target}' names no heading of {destination.relative_to(root)}")
    for p in problems:
        print(p)
    print(f"{len(files)} files checked, {len(problems)} broken links")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
