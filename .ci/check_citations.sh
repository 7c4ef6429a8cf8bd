#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Fails when a comment or a doc cites a page that is not in docs/, or a section that page does not
# have. Checked forms (one line each): `docs/<name>.md`, followed optionally by a section number
# (`docs/ahat.md 4.5`, `section 5.3`, `sec. 2`, lists `7.3, 9.4`, ranges `2.1-2.3`) or a quoted
# heading (`docs/tracking.md, "Pivot calibration"`). A section number must be the number of a
# heading (`## 4.`, `### 4.5`); a quoted name must occur in a heading line or open a bold paragraph
# label (`**Screening**`). Also fails on notes outside the repository (`shared/reference`,
# ARCHITECTURE.md, STYLE.md) and on a numbered citation without the `docs/` prefix (`frames.md 2`).
# Scanned: src apps python tests bench fuzz docs README.md. Called by scripts/test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."

git ls-files -z src apps python tests bench fuzz docs README.md | python3 -c '
import os, re, sys

NUM = r"\d+(?:\.\d+)*(?![\w.]*\w)"
SEP = r"(?:\s*[-\u2013]\s*|,\s*|\s+and\s+)"
CITE = re.compile(
    r"(?<![\w/])docs/([A-Za-z0-9_]+)\.md"
    r"(?:(?:,?\s+(?:sections?|sec\.|\u00a7)\s*|\s+)(" + NUM + r"(?:" + SEP + NUM + r")*)"
    r"|,?\s+\"([^\"]+)\")?")
BARE = re.compile(r"(?<![\w/.-])([A-Za-z0-9_]+)\.md(?:,?\s+(?:sections?|sec\.|\u00a7)\s*|\s+)\d")
OUTSIDE = re.compile(r"shared/reference|(?<![\w/])(?:ARCHITECTURE|STYLE)\.md|\bSTYLE P\d")
HEADING_NUM = re.compile(r"#+\s+(\d+(?:\.\d+)*)[.\s]")

pages = {}
def page(name):
    """(numbers, heading lines, bold labels) of docs/<name>.md, or None when it does not exist."""
    if name not in pages:
        path = os.path.join("docs", name + ".md")
        if not os.path.isfile(path):
            pages[name] = None
        else:
            numbers, headings, labels, fenced = set(), [], [], False
            for line in open(path, encoding="utf-8"):
                if line.startswith("```"):
                    fenced = not fenced
                elif not fenced and line.startswith("#"):
                    headings.append(line.lower())
                    m = HEADING_NUM.match(line)
                    if m:
                        numbers.add(m.group(1))
                elif not fenced:
                    labels += [b.lower() for b in re.findall(r"\*\*([^*]+)\*\*", line)]
            pages[name] = (numbers, headings, labels)
    return pages[name]

def expand(text):
    """Section numbers of a list like `7.3, 9.4` or a range like `2.1-2.3` (every one between)."""
    out = []
    for part in re.split(r",\s*|\s+and\s+", text):
        ends = [e.strip() for e in re.split(r"[-\u2013]", part)]
        if len(ends) == 2:
            a, b = ends[0].split("."), ends[1].split(".")
            if len(a) == len(b) and a[:-1] == b[:-1] and int(a[-1]) <= int(b[-1]):
                out += [".".join(a[:-1] + [str(i)]) for i in range(int(a[-1]), int(b[-1]) + 1)]
                continue
        out += ends
    return out

errors = 0
def fail(where, message):
    global errors
    errors += 1
    print(f"check_citations: {where}: {message}", file=sys.stderr)

for path in sys.stdin.read().split("\0"):
    if not path or not os.path.isfile(path):
        continue
    try:
        lines = open(path, encoding="utf-8").read().split("\n")
    except UnicodeDecodeError:
        continue
    for number, line in enumerate(lines, 1):
        where = f"{path}:{number}"
        if OUTSIDE.search(line):
            fail(where, "cites notes outside the repository; cite docs/ instead")
        for m in BARE.finditer(line):
            fail(where, f"cites {m.group(1)}.md without its docs/ prefix")
        for m in CITE.finditer(line):
            name, sections, heading = m.group(1), m.group(2), m.group(3)
            info = page(name)
            if info is None:
                fail(where, f"docs/{name}.md does not exist")
                continue
            numbers, headings, labels = info
            if sections:
                for s in expand(sections):
                    if s not in numbers:
                        fail(where, f"docs/{name}.md has no section {s}")
            quoted = (heading or "").lower()
            if heading and not any(quoted in h for h in headings) and \
                    not any(b.startswith(quoted) for b in labels):
                fail(where, f"docs/{name}.md has no heading \"{heading}\"")
sys.exit(1 if errors else 0)
'
