#!/usr/bin/env python3
"""ctest: no function body in src/ or include/ runs past 80 lines, two tables of rows aside: the
config schema's key rows (src/config.cpp, schema(): one row per key) and the summary.json key
rows (src/io/summary_keys.cpp, summary_key_groups(): one row per key), read as tables, not logic.

A function is a line that closes a signature with `{` (its statement may span several lines),
up to the `}` at the signature's own indentation. Fails naming each long function, its file,
line and length. With --selftest, checks the scanner on a sample it must flag.
"""
import argparse
import pathlib
import re
import sys

LIMIT = 80
ALLOWED = {("src/config.cpp", "schema"), ("src/io/summary_keys.cpp", "summary_key_groups")}
SIGNATURE_END = re.compile(r"^\s*\S.*\)\s*(const)?\s*(noexcept)?\s*(override)?\s*(try)?\s*\{$")
NOT_A_FUNCTION = re.compile(r"\s*(if|for|while|switch|else|catch|do|return)\b")


def statement_start(lines, i):
    s = i
    while s > 0:
        prev = lines[s - 1].strip()
        if not prev or prev.endswith((";", "{", "}", ":")) or prev.startswith(("//", "#")):
            break
        s -= 1
    return s


def long_functions(text, limit=LIMIT):
    lines = text.split("\n")
    found = []
    inside_until = -1  # a long function's body is not scanned again for its lambdas
    for i, line in enumerate(lines):
        if i <= inside_until or not SIGNATURE_END.match(line):
            continue
        s = statement_start(lines, i)
        head = lines[s]
        before_paren = head.split("(")[0]
        if NOT_A_FUNCTION.match(head) or "=" in before_paren or "[" in before_paren:
            continue
        indent = re.match(r"^(\s*)", head).group(1)
        for k in range(i + 1, len(lines)):
            if lines[k] in (indent + "}", indent + "};"):
                if k - s + 1 > limit:
                    name = re.findall(r"([A-Za-z_~][A-Za-z0-9_:~]*)\s*\(", head)
                    found.append((s + 1, k - s + 1, name[0].split("::")[-1] if name else head))
                    inside_until = k
                break
    return found


def selftest():
    body = "\n".join(f"  x += {k};" for k in range(LIMIT))
    sample = f"int f(int a,\n      int b) {{\n  int x = 0;\n{body}\n  return x;\n}}\n"
    assert [n for _, _, n in long_functions(sample)] == ["f"], long_functions(sample)
    short = "int g() {\n  return 1;\n}\n"
    assert long_functions(short) == []


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--root", required=True)
    args = ap.parse_args()
    selftest()
    root = pathlib.Path(args.root)
    bad = []
    for path in sorted(list(root.glob("src/**/*.cpp")) + list(root.glob("include/**/*.hpp"))):
        rel = path.relative_to(root).as_posix()
        for line, length, name in long_functions(path.read_text()):
            if (rel, name) not in ALLOWED:
                bad.append(f"{rel}:{line}: {name} is {length} lines (at most {LIMIT})")
    if bad:
        print("functions longer than the project's limit (split them):\n  " + "\n  ".join(bad))
        return 1
    print(f"every function of src/ and include/ is at most {LIMIT} lines (schema rows aside)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
