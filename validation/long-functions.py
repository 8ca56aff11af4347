#!/usr/bin/env python3
"""List long Rust functions and long files (issue 41 item 7).

Prints every function longer than --fn-lines (default 150) lines, from its `fn` line to its
closing brace, and every file longer than --file-lines (default 1200) lines before its
tests (the first `#[cfg(test)]` at column 0; a file under a `tests/` folder of src/ or named
`tests.rs` is all test code and is skipped, as is everything after that line).

A long function or file may carry its reason in a comment `// long: <reason>`: for a
function on a line of the comments and attributes just above its `fn` line, for a file in
the comment lines at its head. Such items are listed with their reason; the others are marked
`NO REASON`. With --check the exit status is 1 when any item has no reason.

It reads the source text only (no segfem, no compiler): braces are matched after string,
char and comment contents are blanked, which is enough for rustfmt-formatted code.

Usage: validation/long-functions.py [--fn-lines N] [--file-lines N] [--check] [DIR...]
       (DIR defaults to src/ of the repository holding this script)
"""

import argparse
import os
import re
import sys

FN_RE = re.compile(r"^\s*(?:pub(?:\([^)]*\))?\s+)?(?:const\s+)?(?:async\s+)?(?:unsafe\s+)?"
                   r"(?:extern\s+\"[^\"]*\"\s+)?fn\s+([A-Za-z_][A-Za-z0-9_]*)")
IMPL_RE = re.compile(r"^\s*(?:unsafe\s+)?impl\b(.*?)(?:\{|$)")
REASON_RE = re.compile(r"//\s*long:\s*(.+)")


def blank(text):
    """The text with comments, strings and char literals replaced by spaces (newlines kept),
    so that only code braces remain."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "r" and re.match(r'r#*"', text[i:i + 10]) and not (
                i and (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'r(#*)"', text[i:])
            end = text.find('"' + m.group(1), i + len(m.group(0)))
            j = n if end < 0 else end + 1 + len(m.group(1))
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            j += 1
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "'":
            # A char literal ('x', '\n', '\u{..}', '{') or a lifetime ('a): a literal closes
            # within a few characters.
            m = re.match(r"'(\\u\{[0-9a-fA-F]+\}|\\.|[^\\'])'", text[i:i + 12])
            if m:
                out.append(" " * len(m.group(0)))
                i += len(m.group(0))
            else:
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def test_start(lines):
    """Index of the first line of the file's tests (len(lines) if none)."""
    for k, line in enumerate(lines):
        if line.startswith("#[cfg(test)]"):
            return k
    return len(lines)


def reason_above(lines, k):
    """The `// long:` reason among the comment and attribute lines just above line k."""
    j = k - 1
    while j >= 0:
        s = lines[j].strip()
        if not (s.startswith("//") or s.startswith("#[") or s.startswith("#![")):
            break
        m = REASON_RE.search(s)
        if m:
            return m.group(1).strip()
        j -= 1
    return None


def functions(path, fn_limit):
    """(name, first line, length, reason) of each function longer than fn_limit."""
    with open(path, encoding="utf-8") as f:
        text = f.read()
    lines = text.split("\n")
    code = blank(text).split("\n")
    end = test_start(lines)
    found = []
    impl_name = None
    for k in range(end):
        if code[k] and not code[k][0].isspace():
            m = IMPL_RE.match(code[k])
            impl_name = None
            if m:
                # `impl<'a> Trait for Type<'a> {` -> Type
                head = re.sub(r"^<[^>]*>", "", m.group(1).strip()).strip()
                impl_name = head.split(" for ")[-1].split("<")[0].strip() or None
        m = FN_RE.match(code[k])
        if not m:
            continue
        # The body opens at the first `{` after the name that is not in the signature's
        # generics; a `;` first means a declaration without a body.
        depth, opened, j = 0, False, k
        nest = 0  # () and [] depth in the signature: `[f64; 3]` is not the end
        col = m.end()
        while j < len(code):
            line = code[j]
            while col < len(line):
                ch = line[col]
                if not opened and ch in "([":
                    nest += 1
                elif not opened and ch in ")]":
                    nest -= 1
                elif not opened and ch == ";" and nest == 0:
                    j = len(code)
                    break
                if ch == "{":
                    depth += 1
                    opened = True
                elif ch == "}":
                    depth -= 1
                    if opened and depth == 0:
                        break
                col += 1
            else:
                j, col = j + 1, 0
                continue
            break
        if not opened or j >= len(code):
            continue
        length = j - k + 1
        if length > fn_limit:
            name = f"{impl_name}::{m.group(1)}" if impl_name and code[k][0].isspace() \
                else m.group(1)
            found.append((name, k + 1, length, reason_above(lines, k)))
    return found, lines, end


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--fn-lines", type=int, default=150)
    ap.add_argument("--file-lines", type=int, default=1200)
    ap.add_argument("--check", action="store_true")
    ap.add_argument("dirs", nargs="*")
    args = ap.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    dirs = args.dirs or [os.path.join(root, "src")]
    fns, files = [], []
    for d in dirs:
        for base, subdirs, names in os.walk(d):
            subdirs.sort()
            if "tests" in os.path.relpath(base, d).split(os.sep):
                continue
            for name in sorted(names):
                if not name.endswith(".rs") or name == "tests.rs":
                    continue
                path = os.path.join(base, name)
                rel = os.path.relpath(path, root)
                found, lines, end = functions(path, args.fn_lines)
                fns += [(length, rel, line, fname, reason)
                        for fname, line, length, reason in found]
                if end > args.file_lines:
                    reason = None
                    for line in lines[:end]:
                        t = line.strip()
                        if t and not t.startswith("//") and not t.startswith("#!["):
                            break  # past the file's head
                        m = REASON_RE.search(t)
                        if m:
                            reason = m.group(1).strip()
                            break
                    files.append((end, rel, reason))
    missing = 0
    print(f"functions over {args.fn_lines} lines: {len(fns)}")
    for length, rel, line, fname, reason in sorted(fns, reverse=True):
        missing += reason is None
        print(f"  {length:5} {rel}:{line} {fname}: {reason or 'NO REASON'}")
    print(f"files over {args.file_lines} lines before their tests: {len(files)}")
    for length, rel, reason in sorted(files, reverse=True):
        missing += reason is None
        print(f"  {length:5} {rel}: {reason or 'NO REASON'}")
    print(f"without a reason: {missing}")
    return 1 if args.check and missing else 0


if __name__ == "__main__":
    sys.exit(main())
