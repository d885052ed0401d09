#!/usr/bin/env python3
"""The house's limits on src/ and cli/: no file over 600 lines, no function over 120, each room
of src/ including only the rooms below it, and the default method's folder read in one direction
(docs/architecture.md).

    tests/tools/source_limits.py              # prints each breach; exit 1 if there is one
    tests/tools/source_limits.py --list 80    # every function of 80 lines or more, longest first
    tests/tools/source_limits.py --self-test  # the scanner on shapes it must measure right

CTest runs the first and the last (SourceLimits.FilesFunctionsAndRooms).

A function is a brace-delimited body opened at namespace or class level whose header ends in a
parameter list (with its qualifiers); lambdas and local classes count towards the function that
holds them. Its length is the lines from its header's first line to its closing brace. Comments,
strings and character literals are blanked before the braces are counted. This is a scanner, not
a C++ parser: it reads this project's clang-formatted code, and --self-test checks it on the
shapes that code has.
"""
import argparse
import pathlib
import re
import sys

MAX_FILE_LINES = 600
MAX_FUNCTION_LINES = 120

# The rooms of src/, lowest first: a file may include its own room's headers and those of the
# rooms before it. The file formats and the pipeline are one tier: the formats write the
# pipeline's result types (pipeline/bake_types.h), and the pipeline's cache and shards are read
# and written through them.
ROOMS = [["core"], ["scene"], ["texels"], ["occluders"], ["lightmaps"], ["methods"],
         ["pipeline", "formats"], ["evaluation"]]
_INCLUDE = re.compile(r'^#include "([a-z_]+)/', re.M)

_SCOPE = re.compile(r"\b(namespace|class|struct|union|enum)\b[^()]*$")


def blank_comments_and_strings(text):
    """The text with comments, strings and character literals replaced by spaces (newlines
    kept), so that braces and parentheses inside them are not counted."""
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
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            k = text.find("(", i)
            delim = ")" + text[i + 2:k] + '"'
            j = text.find(delim, k)
            j = n if j < 0 else j + len(delim)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            # A digit separator (1'000) is not a character literal.
            if c == "'" and i > 0 and text[i - 1].isalnum() and i + 1 < n and text[i + 1].isalnum():
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def blank_preprocessor(code):
    """Preprocessor lines (and their continuations) blanked, newlines kept."""
    lines = code.split("\n")
    directive = False
    for k, l in enumerate(lines):
        if directive or l.lstrip().startswith("#"):
            directive = l.rstrip().endswith("\\")
            lines[k] = ""
    return "\n".join(lines)


def functions(text):
    """(name, first line, last line) of each function body in `text`."""
    code = blank_preprocessor(blank_comments_and_strings(text))
    found = []
    # Each open brace: 'scope' (namespace, class, extern "C", enum), 'function', or 'inner'.
    stack = []
    header_start = 0  # where the current declaration's text begins
    line = 1
    for i, c in enumerate(code):
        if c == "\n":
            line += 1
        elif c == ";":
            if not stack or stack[-1][0] == "scope":
                header_start = i + 1
        elif c == "{":
            if stack and stack[-1][0] != "scope":
                stack.append(("inner", None, None))
                continue
            header = code[header_start:i]
            squashed = " ".join(header.split())
            kind = "scope"
            name = None
            if _is_initialiser(squashed):
                kind = "inner"
            elif _is_function_header(squashed):
                kind = "function"
                name = _function_name(squashed)
            first = line - header.lstrip().count("\n")
            stack.append((kind, name, first))
            header_start = i + 1
        elif c == "}":
            if not stack:
                continue
            kind, name, first = stack.pop()
            if kind == "function":
                found.append((name, first, line))
            if not stack or stack[-1][0] == "scope":
                header_start = i + 1
    return found


def _is_initialiser(h):
    """A brace at namespace or class level that opens a value: `x = {`, a lambda's `= [](...)
    {`, a table's `{ {` or `{1}, {`."""
    head = h.split("(")[0]
    return (h.endswith("=") or ("=" in head and "operator" not in head) or h == "" or
            h.endswith(",") or h.startswith("return"))


def _is_function_header(h):
    """A parameter list, then qualifiers (const, override, noexcept, a trailing return type) or
    member initialisers; not a namespace, class or `extern "C"` (its quotes blanked) block."""
    if "(" not in h or not h.endswith(tuple(")abcdefghijklmnopqrstuvwxyz_0123456789>&*]")):
        return False
    return not (_SCOPE.search(h) or re.search(r"\bextern\s*$", h))


def _function_name(h):
    before = h.split("(")[0].split()
    return before[-1] if before else "?"


def room_level(room):
    for level, rooms in enumerate(ROOMS):
        if room in rooms:
            return level
    return None


def room_breaches(root):
    """Each include of a room above the including file's own."""
    out = []
    for path in sorted(list(root.glob("src/*/**/*.cpp")) + list(root.glob("src/*/**/*.h"))):
        rel = path.relative_to(root)
        level = room_level(rel.parts[1])
        if level is None:
            out.append(f"{rel}: in no room of source_limits.py's ROOMS")
            continue
        for m in _INCLUDE.finditer(path.read_text()):
            other = room_level(m.group(1))
            if other is not None and other > level:
                out.append(f"{rel}: includes {m.group(1)}/, a room above {rel.parts[1]}/")
    return out


# Folders read as a one-way pipe: no file includes, directly or not, a file that includes it back
# (a .cpp and its header counting as one), so a reader follows them in one direction.
ONE_WAY = ["src/methods/backprojection"]


def cycle_breaches(root):
    out = []
    for folder in ONE_WAY:
        base = root / folder
        prefix = folder[len("src/"):] + "/"
        graph = {}
        for path in sorted(list(base.glob("*.h")) + list(base.glob("*.cpp"))):
            edges = graph.setdefault(path.stem, set())
            for m in re.finditer(r'^#include "' + re.escape(prefix) + r'(\w+)\.h"', path.read_text(),
                                 re.M):
                if m.group(1) != path.stem:
                    edges.add(m.group(1))
        state = {}

        def visit(node, trail):
            state[node] = 1
            for nxt in sorted(graph.get(node, ())):
                if state.get(nxt) == 1:
                    loop = trail[trail.index(nxt):] + [nxt]
                    out.append(f"{folder}: includes run back: {' -> '.join(loop)}")
                elif nxt not in state:
                    visit(nxt, trail + [nxt])
            state[node] = 2

        for node in sorted(graph):
            if node not in state:
                visit(node, [node])
    return out


def self_test():
    """The scanner on the shapes this code has; exit 1 where it measures one wrong."""
    body = "\n".join(["  x += 1;"] * 5)
    cases = [
        # A free function: its header line to its closing brace.
        ("int f(int x) {\n" + body + "\n  return x;\n}\n", [("f", 1, 8)]),
        # A member function in a class, a lambda inside it counted as its own.
        ("struct S {\n  int g() const {\n    auto l = [&] {\n      return 1;\n    };\n"
         "    return l();\n  }\n  int v = 0;\n};\n", [("g", 2, 7)]),
        # Braces in comments, strings, characters and preprocessor lines are not counted.
        ("#define X {\n// {\nvoid h() {\n  const char* s = \"{\";\n  char c = '{';\n}\n",
         [("h", 3, 6)]),
        # A table's initialiser holds no function; a function after it is found.
        ("const int t[] = {\n  {1}, {2}\n};\nnamespace n {\nvoid k()\n{\n}\n}\n",
         [("k", 5, 7)]),
        # A constructor with member initialisers; control statements are not functions.
        ("A::A(int a)\n    : a_(a) {\n  if (a) {\n    a_ = 2;\n  }\n}\n", [("A::A", 1, 6)]),
    ]
    failed = 0
    for text, want in cases:
        got = functions(text)
        if got != want:
            failed += 1
            print(f"scanner: got {got}, want {want} for:\n{text}")
    return 1 if failed else 0


def breaches(root, max_file, max_function):
    out = room_breaches(root) + cycle_breaches(root)
    for path in sorted(list(root.glob("src/**/*.cpp")) + list(root.glob("src/**/*.h")) +
                       list(root.glob("cli/*.cpp")) + list(root.glob("cli/*.h"))):
        text = path.read_text()
        rel = path.relative_to(root)
        n = text.count("\n")
        if n > max_file:
            out.append(f"{rel}: {n} lines (limit {max_file})")
        for name, first, last in functions(text):
            length = last - first + 1
            if length > max_function:
                out.append(f"{rel}:{first}: function {name} has {length} lines (limit {max_function})")
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", default=str(pathlib.Path(__file__).resolve().parents[2]))
    parser.add_argument("--list", type=int, metavar="N",
                        help="list every function of N lines or more instead")
    parser.add_argument("--self-test", action="store_true",
                        help="check the scanner on shapes it must measure right")
    args = parser.parse_args()
    if args.self_test:
        return self_test()
    root = pathlib.Path(args.root)
    if args.list is not None:
        rows = []
        for path in sorted(list(root.glob("src/**/*.cpp")) + list(root.glob("src/**/*.h")) +
                           list(root.glob("cli/*.cpp"))):
            for name, first, last in functions(path.read_text()):
                if last - first + 1 >= args.list:
                    rows.append((last - first + 1, f"{path.relative_to(root)}:{first}", name))
        for length, where, name in sorted(rows, reverse=True):
            print(f"{length:5d} {where} {name}")
        return 0
    found = breaches(root, MAX_FILE_LINES, MAX_FUNCTION_LINES)
    for b in found:
        print(b)
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
