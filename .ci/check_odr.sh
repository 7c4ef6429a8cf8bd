#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Fails when one qualified type name is defined twice (the one-definition rule across files).

Scans src/ and apps/ for class, struct, union and enum definitions and using-aliases at namespace
scope: in headers, and in .cpp files outside anonymous namespaces (a type in an anonymous
namespace is private to its file). A name defined in two files, or twice in one file with
different bodies, is reported: two translation units that see different definitions of one
tofnav:: type link into undefined behaviour without a diagnostic. Types local to functions and
nested in classes are part of their enclosing definition. A lightweight tokenizer, not a C++
parser: comments, strings and preprocessor lines are skipped; #if branches are both read.
Usage: .ci/check_odr.sh [files...]  (default: git ls-files src apps)
"""
import re
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

# Known duplicates being fixed elsewhere; each entry must still be a duplicate (else it fails too).
ALLOWED: set[str] = set()

TOKEN = re.compile(
    r"""(?P<ws>[ \t\r\f\v]+)
      | (?P<nl>\n)
      | (?P<lcomment>//[^\n]*)
      | (?P<bcomment>/\*.*?\*/)
      | (?P<raw>(?:u8|[uUL])?R"(?P<delim>[^()\\\s]{0,16})\(.*?\)(?P=delim)")
      | (?P<str>(?:u8|[uUL])?"(?:\\.|[^"\\\n])*")
      | (?P<num>\.?\d(?:[eEpP][+-]|'(?=\w)|[\w.])*)
      | (?P<chr>(?:u8|[uUL])?'(?:\\.|[^'\\\n])+')
      | (?P<id>[A-Za-z_]\w*)
      | (?P<punct>::|->|\[\[|\]\]|.)""",
    re.VERBOSE | re.DOTALL,
)


def tokens(text):
    """(token, line) pairs without comments, literals' contents and preprocessor lines."""
    out, pos, line, line_start = [], 0, 1, True
    while pos < len(text):
        if line_start and text[pos] == "#":  # a directive, with its continuation lines
            end = pos
            while True:
                nl = text.find("\n", end)
                if nl < 0:
                    end = len(text)
                    break
                # continuation lines, and block comments spanning lines
                if text[end:nl].rstrip().endswith("\\"):
                    line += 1
                    end = nl + 1
                    continue
                end = nl
                break
            pos = end
            continue
        m = TOKEN.match(text, pos)
        kind, value = m.lastgroup, m.group(0)
        line_start = kind == "nl" or (line_start and kind == "ws")
        if kind in ("str", "raw", "chr"):
            out.append(('""', line))
        elif kind in ("id", "num", "punct"):
            out.append((value, line))
        line += value.count("\n")
        pos = m.end()
    return out


def match_close(toks, i, open_, close):
    """Index of the token closing toks[i] (== open_)."""
    depth = 0
    for j in range(i, len(toks)):
        if toks[j][0] == open_:
            depth += 1
        elif toks[j][0] == close:
            depth -= 1
            if depth == 0:
                return j
    return len(toks) - 1


def skip_attributes(toks, i):
    while i < len(toks):
        if toks[i][0] == "[[":
            while i < len(toks) and toks[i][0] != "]]":
                i += 1
            i += 1
        elif toks[i][0] == "alignas" and i + 1 < len(toks) and toks[i + 1][0] == "(":
            i = match_close(toks, i + 1, "(", ")") + 1
        else:
            return i
    return i


def type_definition(toks, i):
    """At a class-key or enum: (name, end index of the body) when it defines a type, else None."""
    j = i + 1
    if toks[i][0] == "enum" and j < len(toks) and toks[j][0] in ("class", "struct"):
        j += 1
    j = skip_attributes(toks, j)
    name = []
    while j < len(toks) and (re.match(r"[A-Za-z_]", toks[j][0]) or toks[j][0] == "::"):
        if toks[j][0] == "final":
            break
        name.append(toks[j][0])
        j += 1
    if not name or name[-1] == "::":
        return None
    if j < len(toks) and toks[j][0] == "<":  # an explicit or partial specialisation
        k = j
        depth = 0
        while k < len(toks):
            depth += {"<": 1, ">": -1}.get(toks[k][0], 0)
            if depth == 0:
                break
            k += 1
        name += [t for t, _ in toks[j : k + 1]]
        j = k + 1
    if j < len(toks) and toks[j][0] == "final":
        j += 1
    if j >= len(toks) or toks[j][0] not in ("{", ":"):
        return None  # a declaration, or an elaborated type in a declaration
    while j < len(toks) and toks[j][0] not in ("{", ";"):  # bases or the underlying type
        j += 1
    if j >= len(toks) or toks[j][0] == ";":
        return None  # an opaque enum declaration
    return "".join(name), match_close(toks, j, "{", "}")


def definitions(path, toks, found):
    """Adds (qualified name) -> [(path, line, body)] for the namespace-scope definitions."""
    scopes = []  # ("ns", name) for a namespace, ("anon", "") for an anonymous one, ("other", "")
    i = 0
    pending_ns = None
    while i < len(toks):
        t, line = toks[i]
        at_namespace_scope = all(kind == "ns" for kind, _ in scopes)
        if t == "namespace":
            j = i + 1
            parts = []
            while j < len(toks) and toks[j][0] not in ("{", "=", ";"):
                if toks[j][0] not in ("::", "inline"):
                    parts.append(toks[j][0])
                j += 1
            if j < len(toks) and toks[j][0] == "{":
                pending_ns = parts
                i = j
                continue
            i = j + 1
            continue
        if t == "extern" and i + 2 < len(toks) and toks[i + 1][0] == '""' and toks[i + 2][0] == "{":
            scopes.append(("ns", ""))
            i += 3
            continue
        if t == "{":
            if pending_ns is not None:
                if pending_ns:
                    scopes.append(("ns", "::".join(pending_ns)))
                else:
                    scopes.append(("anon", ""))
                pending_ns = None
            else:
                scopes.append(("other", ""))
            i += 1
            continue
        if t == "}":
            if scopes:
                scopes.pop()
            i += 1
            continue
        if at_namespace_scope and t in ("class", "struct", "union", "enum"):
            definition = type_definition(toks, i)
            if definition:
                name, end = definition
                record(found, scopes, name, path, line, toks[i : end + 1])
                i = end + 1
                continue
        if (at_namespace_scope and t == "using" and i + 2 < len(toks)
                and re.match(r"[A-Za-z_]", toks[i + 1][0]) and toks[i + 2][0] == "="):
            end = i
            while end < len(toks) and toks[end][0] != ";":
                end += 1
            record(found, scopes, toks[i + 1][0], path, line, toks[i : end + 1])
            i = end + 1
            continue
        i += 1


def record(found, scopes, name, path, line, body):
    qualified = "::".join([n for kind, n in scopes if kind == "ns" and n] + [name])
    found[qualified].append((path, line, " ".join(t for t, _ in body)))


def main():
    root = Path(__file__).resolve().parent.parent
    files = sys.argv[1:] or subprocess.run(
        ["git", "ls-files", "src", "apps"], cwd=root, check=True, capture_output=True, text=True
    ).stdout.split()
    found = defaultdict(list)
    for name in files:
        if name.endswith((".hpp", ".cpp", ".h")):
            definitions(name, tokens((root / name).read_text(encoding="utf-8")), found)
    status = 0
    for qualified, places in sorted(found.items()):
        in_files = {path for path, _, _ in places}
        bodies = {body for _, _, body in places}
        duplicate = len(in_files) > 1 or len(bodies) > 1
        where = ", ".join(f"{path}:{line}" for path, line, _ in places)
        if duplicate and qualified in ALLOWED:
            print(f"check_odr: allowed for now: {qualified} defined in {where}", file=sys.stderr)
        elif duplicate:
            what = "different bodies" if len(bodies) > 1 else "the same body"
            print(f"check_odr: {qualified} defined more than once ({what}): {where}",
                  file=sys.stderr)
            status = 1
    for qualified in sorted(ALLOWED):
        places = found.get(qualified, [])
        if len({p for p, _, _ in places}) < 2 and len({b for _, _, b in places}) < 2:
            print(f"check_odr: {qualified} is no longer duplicated: remove it from ALLOWED",
                  file=sys.stderr)
            status = 1
    return status


if __name__ == "__main__":
    sys.exit(main())
