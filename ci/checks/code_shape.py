#!/usr/bin/env python3
"""The code's shape, as docs/layering.md states it (issue 26's bars):

  - no function longer than 150 lines and no file longer than 900 in non-test
    code (test and benchmark files are exempt);
  - nothing under tracker/ includes a sim/ header.

Usage: code_shape.py ROOT [--report]. Exits 1 and names each violation.
Functions are found by their braces after comments and strings are blanked:
a block opened right after `)` (optionally const/override/noexcept/-> T), not
inside another function and not a control statement, is a function; a lambda
counts as part of the function around it. A heuristic, not a C++ parser.
"""
import os
import re
import sys

MAX_FUNCTION_LINES = 150
MAX_FILE_LINES = 900
CODE_DIRS = ["common", "geometry", "sequence_format", "sim", "tracker", "ci", "cli"]
CONTROL = re.compile(r"^\s*(if|for|while|switch|catch|else|do|try|return)\b")
SIGNATURE_END = re.compile(
    r"\)\s*(const\s*)?(noexcept\s*)?(override\s*)?(final\s*)?(->\s*[\w:<>,\s\*&]+)?\s*$")


def blank_comments_and_strings(src):
    out, i, n = [], 0, len(src)
    while i < n:
        c = src[i]
        if src.startswith("//", i):
            j = src.find("\n", i)
            i = n if j < 0 else j
        elif src.startswith("/*", i):
            j = src.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * src.count("\n", i, j))
            i = j
        elif src.startswith('R"', i) and re.match(r'R"([^(\s]*)\(', src[i:]):
            m = re.match(r'R"([^(\s]*)\(', src[i:])
            end = ")" + m.group(1) + '"'
            j = src.find(end, i)
            j = n if j < 0 else j + len(end)
            out.append('""' + "\n" * src.count("\n", i, j))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and src[j] != c and src[j] != "\n":
                j += 2 if src[j] == "\\" else 1
            out.append(c + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(text):
    """(lines, first line, name) of each outermost function body, and the line count."""
    stack, found, line, last = [], [], 1, 0
    for i, c in enumerate(text):
        if c == "\n":
            line += 1
        elif c == "{":
            head = " ".join(text[last:i].split())
            head_no_init = re.sub(r"\)\s*:\s.*$", ")", head)
            in_function = any(is_fn for is_fn, _, _ in stack)
            is_fn = (not in_function and "(" in head and not CONTROL.match(head)
                     and bool(SIGNATURE_END.search(head_no_init)))
            name = ""
            if is_fn:
                m = re.search(r"([\w:~<>]+)\s*\(", head)
                name = m.group(1) if m else head[:40]
            stack.append((is_fn, line, name))
            last = i + 1
        elif c == "}":
            if stack:
                is_fn, start, name = stack.pop()
                if is_fn:
                    found.append((line - start + 1, start, name))
            last = i + 1
        elif c == ";":
            last = i + 1
    return found, line - 1 if text.endswith("\n") else line


def self_test():
    """The checker on a made-up tree: what must be caught is, what must pass does."""
    import tempfile
    with tempfile.TemporaryDirectory() as root:
        def write(rel, text):
            os.makedirs(os.path.dirname(os.path.join(root, rel)), exist_ok=True)
            with open(os.path.join(root, rel), "w") as f:
                f.write(text)
        body = lambda n: "int F() {\n" + "  x();\n" * (n - 2) + "}\n"
        write("sim/ok.cc", body(150) + "// a } in a comment\nconst char* s = \"{\";\n" + body(150))
        write("sim/long_fn.cc", "namespace a {\nstruct S {\n  void G() const " + body(151)[8:] + "};\n}\n")
        write("sim/long_file.cc", "int x;\n" * 901)
        write("tracker/t.h", '#include "sim/scene/scene.h"\n')
        write("tracker/t_test.cc", body(400))
        sys.argv = ["code_shape.py", root]
        import io, contextlib
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            rc = main()
        text = out.getvalue()
        expected = ["sim/long_fn.cc:3: G is 151 lines", "sim/long_file.cc: 901 lines", "tracker/t.h: includes sim/"]
        missing = [e for e in expected if e not in text]
        extra = [l for l in text.splitlines()[1:] if not any(e in l for e in expected)]
        if rc != 1 or missing or extra:
            print("self-test failed: rc", rc, "missing", missing, "unexpected", extra)
            return 1
    print("self-test passed")
    return 0


def main():
    if "--self-test" in sys.argv:
        return self_test()
    root = sys.argv[1] if len(sys.argv) > 1 else "."
    report = "--report" in sys.argv
    problems, longest_fn, longest_file = [], (0, "", ""), (0, "")
    for top in CODE_DIRS:
        for folder, _, files in os.walk(os.path.join(root, top)):
            for name in sorted(files):
                if not name.endswith((".cc", ".h")):
                    continue
                path = os.path.join(folder, name)
                rel = os.path.relpath(path, root)
                with open(path, encoding="utf-8", errors="replace") as f:
                    src = f.read()
                if rel.startswith("tracker" + os.sep):
                    for m in re.finditer(r'#include\s+"(sim/[^"]+)"', src):
                        problems.append(f"{rel}: includes {m.group(1)} (the tracker never includes the sim)")
                if name.endswith(("_test.cc", "_benchmark.cc")) or "test_util" in name:
                    continue
                found, lines = functions(blank_comments_and_strings(src))
                longest_file = max(longest_file, (lines, rel))
                if lines > MAX_FILE_LINES:
                    problems.append(f"{rel}: {lines} lines (at most {MAX_FILE_LINES})")
                for length, start, fn in found:
                    longest_fn = max(longest_fn, (length, f"{rel}:{start}", fn))
                    if length > MAX_FUNCTION_LINES:
                        problems.append(f"{rel}:{start}: {fn} is {length} lines (at most {MAX_FUNCTION_LINES})")
    if report or problems:
        print(f"longest function: {longest_fn[2]} ({longest_fn[1]}), {longest_fn[0]} lines; "
              f"longest file: {longest_file[1]}, {longest_file[0]} lines")
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
