#!/usr/bin/env python3
"""Doxygen's INPUT_FILTER for include/pyrseg/*.hpp: reads the headers' plain // comments as documentation.

The headers keep the project's comment style (//, no Doxygen markup); this filter turns, line for line (so that
Doxygen's line numbers stay right):
  - #pragma once and the comment block after it into the file's description (\\file);
  - a comment block directly above a declaration into that declaration's documentation (///);
  - a comment after a member or enumerator on its line, and the comment lines aligned under it, into that member's
    documentation (///<).
Comment blocks followed by a blank line are notes on what follows, not on one declaration, and stay plain comments.
"""
import re
import sys

COMMENT = re.compile(r"^(\s*)//(?!/)(.*)$")
TRAILING = re.compile(r"^(\s*\S.*?[;,{])(\s*)//(?!/)(.*)$")


def convert(lines):
    out = list(lines)
    n = len(lines)
    i = 0
    seen_code = False
    pragma_seen = False
    trailing_column = None  # column of the last trailing comment, for the lines aligned under it
    while i < n:
        line = lines[i]
        if line.startswith("#pragma once"):
            # The file's description starts here (Doxygen needs no include guard).
            out[i] = "/// \\file"
            pragma_seen = True
            i += 1
            continue
        m = COMMENT.match(line)
        if m:
            indent = len(m.group(1))
            if trailing_column is not None and indent == trailing_column:
                out[i] = f"{m.group(1)}///<{m.group(2)}"
                i += 1
                continue
            trailing_column = None
            start = i
            while i < n and COMMENT.match(lines[i]) and len(COMMENT.match(lines[i]).group(1)) == indent:
                i += 1
            following = lines[i] if i < n else ""
            if pragma_seen and not seen_code:
                # The file's description: everything up to the first declaration or include.
                for k in range(start, i):
                    out[k] = "///" + COMMENT.match(lines[k]).group(2)
                seen_code = True
                continue
            documents = following.strip() and not following.lstrip().startswith(("#", "}", "//", "public:",
                                                                                     "private:"))
            if documents:
                for k in range(start, i):
                    c = COMMENT.match(lines[k])
                    out[k] = f"{c.group(1)}///{c.group(2)}"
            continue
        trailing_column = None
        if line.strip():
            seen_code = True
        t = TRAILING.match(line)
        if t and not line.lstrip().startswith("#"):
            out[i] = f"{t.group(1)}{t.group(2)}///<{t.group(3)}"
            trailing_column = len(t.group(1)) + len(t.group(2))
        i += 1
    return out


def main():
    with open(sys.argv[1], encoding="utf-8") as f:
        text = f.read()
    lines = text.split("\n")
    sys.stdout.write("\n".join(convert(lines)))


if __name__ == "__main__":
    main()
