#!/usr/bin/env python3
"""Checks the house limits on size: no function body over 120 lines, no file over 500 lines.

The limits hold for the C++ sources and headers of the library and of the Python module
(src/ and python/src/): a long body is a sequence of steps that wants names, and a long file
holds more than one idea (docs/ARCHITECTURE.md, /CRAFT "files hold one concept").

A body's length counts the lines from the one holding its opening brace to the one holding
its closing brace, both included (a one-line body is 1). A file's length is its line count.

Functions are found by a brace-matching scanner, not a compiler: comments, string and
character literals (raw strings and digit separators included) and preprocessor lines are
blanked first, then every brace block at namespace or class scope is classified by the text
that leads up to it since the last `;`, `{` or `}` of that scope:

- `namespace`, `class`, `struct`, `union`, `enum` and `extern "C"` blocks (after an optional
  `template <...>`) are containers: what is inside them is classified in turn;
- a block opened after a `)`, possibly followed by qualifiers (`const`, `noexcept`,
  `override`, `final`, `&`, `&&`, `mutable`, `-> T`) or by a constructor's initialiser list,
  is a function; everything inside it (lambdas, local classes, blocks) counts towards it;
- any other block (a braced initialiser, an array's values) is neither and is skipped.

Exit status 0 when every file keeps the limits, 1 with one line per finding otherwise
(`path:line: name: N lines (limit L)`). Run by the test suite (tests/CMakeLists.txt), which
also runs `--self-test`: synthetic sources that show a 121-line function is caught and a
121-line namespace or class is not. Paths given on the command line (files or folders) are
checked instead of src/ and python/src/.
"""
import pathlib
import re
import sys
import tempfile

MAX_BODY_LINES = 120
MAX_FILE_LINES = 500
SUFFIXES = {".cpp", ".cc", ".cxx", ".h", ".hpp", ".hh", ".inl", ".ipp"}
DEFAULT_ROOTS = ("src", "python/src")

IDENT_CHAR = re.compile(r"[0-9A-Za-z_]")


def literal_end(text, i):
    """The offset of the quote that closes the literal whose opening quote is at i (or of the
    end of the line or text, for one left open)."""
    j = i + 1
    while j < len(text) and text[j] != text[i] and text[j] != "\n":
        j += 2 if text[j] == "\\" else 1
    return j


def blank(text):
    """The text with comments, literals and preprocessor lines replaced by spaces.

    Newlines are kept, so that an offset's line number is the same in both texts. A string
    literal keeps its quotes (`""`), so that `extern "C"` still reads as such.
    """
    out = list(text)
    n = len(text)
    i = 0
    line_start = True  # only white space since the last newline: a `#` opens a directive

    def wipe(a, b):
        for k in range(a, b):
            if out[k] != "\n":
                out[k] = " "

    while i < n:
        c = text[i]
        if c == "\n":
            line_start = True
            i += 1
            continue
        if line_start and c == "#":
            j = i
            while j < n and text[j] != "\n":
                if text[j] == "\\" and j + 1 < n and text[j + 1] == "\n":
                    j += 2
                    continue
                # A comment that opens on a directive line ends where the comment ends.
                if text.startswith("/*", j):
                    end = text.find("*/", j + 2)
                    j = n if end < 0 else end + 2
                    continue
                if text.startswith("//", j):
                    while j < n and text[j] != "\n":
                        j += 1
                    break
                j += 1
            wipe(i, j)
            i = j
            continue
        if not c.isspace():
            line_start = False
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            wipe(i, j)
            i = j
            continue
        if text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            wipe(i, j)
            i = j
            continue
        if c == '"':
            raw = re.search(r"(?:u8|u|U|L)?R$", text[max(0, i - 3):i])
            if raw and (i - len(raw.group(0)) == 0 or not IDENT_CHAR.match(text[i - len(raw.group(0)) - 1])):
                m = re.match(r'"([^ ()\\\t\n]{0,16})\(', text[i:])
                if m:
                    close = ")" + m.group(1) + '"'
                    end = text.find(close, i + len(m.group(0)))
                    end = n if end < 0 else end + len(close)
                    wipe(i + 1, end - 1)
                    i = end
                    continue
            j = literal_end(text, i)
            wipe(i + 1, min(j, n))
            i = j + 1
            continue
        if c == "'":
            # A digit separator (1'000'000) is inside a number: the token before it starts
            # with a digit.
            k = i
            while k > 0 and (IDENT_CHAR.match(text[k - 1]) or text[k - 1] in ".'"):
                k -= 1
            if k < i and text[k].isdigit():
                i += 1
                continue
            j = literal_end(text, i)
            wipe(i + 1, min(j, n))
            i = j + 1
            continue
        i += 1
    return "".join(out)


CONTAINER = re.compile(r"^(?:template\s*<.*>\s*)?(?:(?:namespace|class|struct|union|enum)\b|extern\s*\"\")", re.S)
ACCESS = re.compile(r"^\s*(?:public|private|protected)\s*:(?!:)")
QUALIFIERS = r"(?:\s|const\b|volatile\b|noexcept\b|override\b|final\b|mutable\b|&|\(\))*"
FUNCTION_END = re.compile(r"\)" + QUALIFIERS + r"(?:->[^;]*)?$", re.S)
NAME_BEFORE_PAREN = re.compile(r"((?:~?[A-Za-z_]\w*\s*::\s*)*(?:operator\s*[^\s(]+|~?[A-Za-z_]\w*))\s*(?:<[^()]*>)?\s*$")


def flatten_braces(header):
    """The header with each balanced `{...}` (a braced member initialiser) turned into `()`."""
    prev = None
    while prev != header:
        prev = header
        header = re.sub(r"\{[^{}]*\}", "()", header)
    return header


def classify(header):
    """'container', 'function' or 'other' for a block whose leading text is `header`."""
    header = ACCESS.sub("", header).strip()
    while ACCESS.match(header):
        header = ACCESS.sub("", header).strip()
    header = re.sub(r"\[\[.*?\]\]", " ", header).strip()
    if CONTAINER.match(header):
        return "container"
    flat = flatten_braces(header)
    if FUNCTION_END.search(flat):
        return "function"
    return "other"


def function_name(header):
    """The function's (qualified) name as the header spells it, or '?'."""
    flat = re.sub(r"\s+", " ", flatten_braces(ACCESS.sub("", header)))
    flat = re.sub(r"^template\s*<.*?>\s*(?=[A-Za-z_])", "", flat)
    lambda_at = flat.find("[")
    paren = flat.find("(")
    if lambda_at >= 0 and (paren < 0 or lambda_at < paren):
        var = re.search(r"([A-Za-z_]\w*)\s*=\s*$", flat[:lambda_at])
        return (var.group(1) + " (lambda)") if var else "lambda"
    while paren >= 0:
        m = NAME_BEFORE_PAREN.search(flat[:paren])
        if m:
            return re.sub(r"\s+", "", m.group(1))
        paren = flat.find("(", paren + 1)
    return "?"


def long_functions(text, limit=MAX_BODY_LINES):
    """(line, name, length) of each function body in `text` longer than `limit` lines."""
    code = blank(text)
    found = []
    # Each open block: (kind, line of its brace, name, start of its scope's current header).
    stack = []
    header_start = 0
    line = 1
    depth_in_function = 0  # braces open inside the innermost function, itself included
    for i, c in enumerate(code):
        if c == "\n":
            line += 1
        elif depth_in_function:
            if c == "{":
                depth_in_function += 1
            elif c == "}":
                depth_in_function -= 1
                if depth_in_function == 0:
                    kind, first, name, _ = stack.pop()
                    length = line - first + 1
                    if length > limit:
                        found.append((first, name, length))
                    header_start = i + 1
        elif c == ";":
            header_start = i + 1
        elif c == "{":
            header = code[header_start:i]
            kind = classify(header)
            name = function_name(header) if kind == "function" else ""
            stack.append((kind, line, name, header_start))
            if kind == "function":
                depth_in_function = 1
            else:
                header_start = i + 1
        elif c == "}":
            if not stack:
                continue
            kind, _, _, outer_header_start = stack.pop()
            # A braced initialiser belongs to the statement around it (`: a_{1}, b_{2} {`);
            # a container ends a statement.
            header_start = outer_header_start if kind == "other" else i + 1
    return found


def check_file(path, shown):
    text = path.read_text(errors="replace")
    findings = []
    lines = text.count("\n") + (0 if text.endswith("\n") or not text else 1)
    if lines > MAX_FILE_LINES:
        findings.append(f"{shown}:1: file: {lines} lines (limit {MAX_FILE_LINES})")
    for first, name, length in long_functions(text):
        findings.append(f"{shown}:{first}: {name}: {length} lines (limit {MAX_BODY_LINES})")
    return findings


def source_files(paths):
    for p in paths:
        if p.is_file():
            yield p
        elif p.is_dir():
            yield from sorted(f for f in p.rglob("*") if f.is_file() and f.suffix in SUFFIXES)


def self_test():
    """Synthetic sources: the limits are caught exactly at 121 lines, containers never."""
    def body(n):  # a block spanning n lines, its braces included
        return "{\n" + "  x += 1;\n" * (n - 2) + "}\n"

    cases = [
        ("a 121-line function", "int f(int x) " + body(121), [("f", 121)]),
        ("a 120-line function", "int f(int x) " + body(120), []),
        ("a 121-line namespace", "namespace n " + body(121), []),
        ("a 121-line class", "class C " + body(121) + ";\n", []),
        ("a 121-line struct template", "template <typename T>\nstruct S : T " + body(121) + ";\n", []),
        ("a 121-line member function in a class",
         "class C {\n public:\n  void g() const noexcept " + body(121) + "};\n", [("g", 121)]),
        ("a constructor with an initialiser list",
         "A::A(int a) : a_(a), b_{a, 2} " + body(121), [("A::A", 121)]),
        ("a trailing return type", "auto h() -> std::vector<int> " + body(121), [("h", 121)]),
        ("a lambda counts towards its function",
         "void k() {\n  auto l = [](int y) " + body(60) + "  auto m = [&] " + body(59) + "}\n", [("k", 121)]),
        ("braces in comments and literals",
         "void p() {\n  // }\n  const char* s = \"}\";\n  char c = '}';\n  auto r = R\"x(}\n)x\";\n"
         "  /* } */\n  int big = 1'000;\n" + "  x += 1;\n" * 112 + "}\n", [("p", 121)]),
        ("a braced array at namespace scope", "const int table[] = " + body(121)[:-1] + ";\n", []),
        ("a preprocessor line with a brace",
         "#define OPEN {\nvoid q() " + body(121), [("q", 121)]),
    ]
    failures = []
    for what, text, expected in cases:
        got = [(name, length) for _, name, length in long_functions(text)]
        if got != expected:
            failures.append(f"self-test: {what}: expected {expected}, found {got}")
    with tempfile.TemporaryDirectory() as tmp:
        long_file = pathlib.Path(tmp) / "long.cpp"
        long_file.write_text("int x;\n" * (MAX_FILE_LINES + 1))
        if not check_file(long_file, "long.cpp"):
            failures.append(f"self-test: a {MAX_FILE_LINES + 1}-line file is not caught")
        ok_file = pathlib.Path(tmp) / "ok.cpp"
        ok_file.write_text("int x;\n" * MAX_FILE_LINES)
        if check_file(ok_file, "ok.cpp"):
            failures.append(f"self-test: a {MAX_FILE_LINES}-line file is caught")
    for f in failures:
        print(f)
    return 1 if failures else 0


def main(argv):
    if argv[1:] == ["--self-test"]:
        return self_test()
    root = pathlib.Path(__file__).resolve().parent.parent
    paths = [pathlib.Path(a).resolve() for a in argv[1:]] or [root / r for r in DEFAULT_ROOTS]
    findings = []
    for f in source_files(paths):
        try:
            shown = f.relative_to(root)
        except ValueError:
            shown = f
        findings.extend(check_file(f, shown))
    for f in findings:
        print(f)
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
