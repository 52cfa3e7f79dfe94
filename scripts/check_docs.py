#!/usr/bin/env python3
"""Runs the commands the documentation shows and compares their output with what it shows.

Reads README.md, examples/README.md and docs/*.md. A fenced block whose lines start with
"$ " is a transcript: each "$ " line is a command (run with bash), the lines after it, up to
the next "$ " line, are its output as shown (standard output and standard error together),
and a last line "exit N" is its exit status (0 when absent). A shown output matches when,
line by line after trailing spaces are dropped:

  * a line "..." stands for any number of lines (none included);
  * "..." inside a line, or "(...)", stands for any text;
  * "~" before a number marks a number that varies from run to run (a time, a rate, the
    machine's memory): any number matches it. Every other number must be as shown.

The commands of one file run in order in one sandbox folder (so a file can build on what an
earlier block wrote), a fresh folder per file, with `trivox` on the PATH and the repository's
examples/, tests/ and scripts/ and ../shared beside it as in a checkout. A block preceded by
the comment

    <!-- docs-check: parse-only REASON -->

(a whole duck, a kill -9, an input the docs do not give) is not run: each `trivox` command
in it is parsed against the program's options (the subcommand exists, every option is one
of its options, as `trivox SUBCOMMAND --help` lists them), as are the `trivox` lines of
blocks without transcripts (```sh blocks of commands).

A transcript that shows exit 2 (a usage error) is not parsed: it shows a command line the
program refuses. In a block of commands, a line's text after two spaces or more is a
description (a synopsis), and an upper-case word where a subcommand stands is a placeholder.

Python: the ```python blocks of a file run in order in one interpreter and one namespace (in
the same sandbox folder, with the build's module first on the import path); a ```pycon block
is a doctest (">>> " lines, their output below them; "..." in the output stands for any
text), run in the same namespace. A Python block after the parse-only comment is compiled,
not run.

Exit status 0 when every command matches and parses, 1 with one finding per line otherwise.
Run by the test suite in the release pass (python/CMakeLists.txt, Docs.*):
  scripts/check_docs.py --trivox build/release/bin/trivox --python-path build/release/python [FILE...]
"""
import argparse
import json
import os
import pathlib
import re
import shlex
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared"
FENCE = re.compile(r"^(\s*)```(\w*)")
DIRECTIVE = re.compile(r"<!--\s*docs-check:\s*parse-only\b(.*?)-->")
# A line of a block of commands that runs trivox (by name or by path, after an environment
# setting or a pipe), not one of output ("trivox: error: ...", "trivox 0.1.0").
COMMAND_LINE = re.compile(r"(^\s*(\w+=\S*\s+)*|[|;&]\s*)(\S*/)?trivox\s+-{0,2}[a-z]")
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


class Block:
    def __init__(self, path, line, lines, parse_only, lang):
        self.path, self.line, self.lines, self.parse_only, self.lang = path, line, lines, parse_only, lang

    def transcript(self):
        return any(l.startswith("$ ") for l in self.lines)


def blocks_of(path):
    text = path.read_text().splitlines()
    out = []
    i = 0
    while i < len(text):
        m = FENCE.match(text[i])
        if not m:
            i += 1
            continue
        start, lang = i, m.group(2)
        body = []
        i += 1
        while i < len(text) and not FENCE.match(text[i]):
            body.append(text[i])
            i += 1
        before = "\n".join(text[max(0, start - 3):start])
        out.append(Block(path, start + 1, body, bool(DIRECTIVE.search(before)), lang))
        i += 1
    return out


def commands_of(block):
    """(command, shown output lines, shown exit status) of each "$ " line of a transcript."""
    out = []
    for line in block.lines:
        if line.startswith("$ "):
            out.append([line[2:], [], 0])
        elif out:
            out[-1][1].append(line.rstrip())
    for c in out:
        while c[1] and c[1][-1] == "":
            c[1].pop()
        if c[1] and re.fullmatch(r"exit \d+", c[1][-1]):
            c[2] = int(c[1].pop().split()[1])
    return out


def line_pattern(shown):
    """The regular expression a shown line stands for."""
    parts = re.split(r"(\(\.\.\.\)|\.\.\.|~" + NUMBER.pattern + ")", shown)
    rx = ""
    for p in parts:
        if p in ("(...)", "..."):
            rx += ".*"
        elif p.startswith("~"):
            rx += NUMBER.pattern
        else:
            rx += re.escape(p)
    return re.compile(rx)


def matches(shown, actual):
    """Whether the actual lines match the shown ones ("..." lines match any lines)."""
    memo = {}

    def at(i, j):
        if (i, j) in memo:
            return memo[(i, j)]
        if i == len(shown):
            r = j == len(actual)
        elif shown[i] == "...":
            r = any(at(i + 1, k) for k in range(j, len(actual) + 1))
        else:
            r = j < len(actual) and line_pattern(shown[i]).fullmatch(actual[j]) is not None and at(i + 1, j + 1)
        memo[(i, j)] = r
        return r

    sys.setrecursionlimit(max(10000, 4 * (len(shown) + len(actual))))
    return at(0, 0)


_help = {}


def help_of(trivox, chain):
    """(options, subcommands) that `trivox CHAIN... --help` lists; None when CHAIN is no
    subcommand."""
    key = tuple(chain)
    if key not in _help:
        r = subprocess.run([trivox, *chain, "--help"], capture_output=True, text=True)
        if r.returncode != 0:
            _help[key] = None
        else:
            opts, subs, in_subs = set(), set(), False
            for line in r.stdout.splitlines():
                if line.strip().upper().startswith("SUBCOMMANDS"):
                    in_subs = True
                    continue
                m = re.match(r"\s+((?:-[-\w]+,?)+)", line)
                if m:
                    opts.update(o for o in m.group(1).split(",") if o)
                    in_subs = False
                elif in_subs and re.match(r"\s+[a-z][\w-]*", line):
                    subs.add(line.split()[0])
            _help[key] = (opts, subs)
    return _help[key]


def options_of(trivox, chain):
    """The options of `trivox CHAIN...` (the program's own with an empty chain); None when
    CHAIN is no subcommand."""
    h = help_of(trivox, chain)
    return None if h is None else h[0]


def parse_problems(trivox, command):
    """What in one shell line's `trivox` commands the program would not take."""
    problems = []
    try:
        words = shlex.split(command, comments=True)
    except ValueError as e:
        return [f"cannot split the command: {e}"]
    # Each trivox invocation runs to the next shell operator.
    i = 0
    while i < len(words):
        w = words[i]
        if os.path.basename(w) != "trivox":
            i += 1
            continue
        j = i + 1
        args = []
        while j < len(words) and words[j] not in ("|", "&&", "||", ";", "&", ">", "<", "2>&1"):
            args.append(words[j])
            j += 1
        sub = next((a for a in args if not a.startswith("-")), None)
        if sub is not None and sub.isupper():  # a placeholder: trivox COMMAND --help
            i = j
            continue
        chain = [sub] if sub is not None else []
        if chain and help_of(trivox, chain) is None:
            problems.append(f"'{sub}' is no subcommand of trivox")
            i = j
            continue
        # A subcommand's own subcommand (trivox cluster slurm): the next word when listed.
        rest = args[args.index(sub) + 1:] if sub is not None else []
        if rest and help_of(trivox, chain)[1] and rest[0] in help_of(trivox, chain)[1]:
            chain.append(rest[0])
        known = options_of(trivox, chain) | options_of(trivox, [])
        for a in args:
            if a == "--":
                break
            if a.startswith("-") and not NUMBER.fullmatch(a):
                name = a.split("=", 1)[0]
                if name not in known:
                    problems.append(f"trivox {' '.join(chain)} has no option {name}")
        i = j
    return problems


PYTHON_LANGS = ("python", "pycon")

# Runs a file's Python blocks in one namespace (a child process, in the sandbox): reads a JSON
# list of [lang, name, first line, source, compile only] from standard input, prints one JSON
# finding per line.
PYTHON_RUNNER = r'''
import doctest, json, sys, traceback
blocks = json.load(sys.stdin)
globs = {"__name__": "__main__"}
flags = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
for lang, name, line, source, compile_only in blocks:
    where = f"{name}:{line}"
    try:
        if lang == "pycon":
            test = doctest.DocTestParser().get_doctest(source, globs, where, name, line)
            if compile_only:
                for ex in test.examples:
                    compile(ex.source, where, "exec")
                continue
            report = []
            runner = doctest.DocTestRunner(optionflags=flags)
            runner.run(test, out=report.append, clear_globs=False)
            globs.update(test.globs)  # DocTest works on a copy; later blocks build on it
            if runner.failures:
                print(json.dumps([where, "".join(report)]), flush=True)
        else:
            code = compile(source, where, "exec")
            if not compile_only:
                exec(code, globs)
    except BaseException:
        print(json.dumps([where, traceback.format_exc(limit=4)]), flush=True)
'''


def sandbox(tmp, trivox, python_path):
    """A folder laid out as a checkout: examples/, tests/, scripts/ and docs/ beside the
    commands, ../shared beside that; `trivox` and this interpreter as `python3` on the PATH,
    the build's Python module first on the import path."""
    repo = tmp / "repo"
    repo.mkdir()
    for name in ("examples", "tests", "scripts", "docs", "build"):
        if (ROOT / name).exists():
            (repo / name).symlink_to(ROOT / name)
    if SHARED.exists():
        (tmp / "shared").symlink_to(SHARED)
    bin_dir = tmp / "bin"
    bin_dir.mkdir()
    (bin_dir / "trivox").symlink_to(pathlib.Path(trivox).resolve())
    (bin_dir / "python3").symlink_to(sys.executable)
    env = dict(os.environ)
    env["PATH"] = f"{bin_dir}:{env['PATH']}"
    if python_path:
        env["PYTHONPATH"] = os.pathsep.join(p for p in (str(pathlib.Path(python_path).resolve()),
                                                          env.get("PYTHONPATH")) if p)
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    env["MPLBACKEND"] = "Agg"  # matplotlib without a display
    env.pop("TRIVOX_SIMD", None)
    return repo, env


def run_python(blocks, rel, cwd, env, run, findings, timeout):
    """Runs (or, with run False, compiles) the Python blocks of one file; returns how many."""
    todo = [[b.lang, str(rel), b.line + 1, "\n".join(b.lines) + "\n", b.parse_only or not run] for b in blocks]
    if not todo:
        return 0
    try:
        r = subprocess.run([sys.executable, "-c", PYTHON_RUNNER], input=json.dumps(todo), cwd=cwd, env=env,
                           capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        findings.append(f"{rel}: its Python blocks ran over {timeout} s")
        return len(todo)
    for line in r.stdout.splitlines():
        try:
            where, what = json.loads(line)
        except ValueError:
            continue
        findings.append(f"{where}: the Python block fails:\n" + "\n".join("    | " + l for l in what.splitlines()))
    if r.returncode != 0:
        findings.append(f"{rel}: the Python runner exited {r.returncode}:\n" +
                        "\n".join("    | " + l for l in r.stderr.splitlines()[-8:]))
    return len(todo)


def run_transcript(block, trivox, cwd, env, findings, timeout):
    """Runs (or parses) each command of a transcript; returns (run, parsed)."""
    rel = shown_path(block.path)
    ran = parsed = 0
    commands = commands_of(block)
    # The real models of ../shared (README's "Real data") may be absent: then such a block is
    # parsed, not run, and says so.
    skip = not SHARED.exists() and any("../shared" in c or "shared_scenes" in c for c, _, _ in commands)
    if skip and not block.parse_only:
        print(f"check_docs: {rel}:{block.line}: parsed only: it reads ../shared, which is absent")
    for command, shown, status in commands:
        where = f"{rel}:{block.line + 1 + block.lines.index('$ ' + command)}"
        # A transcript showing exit 2 shows a command line the program refuses.
        for p in parse_problems(trivox, command) if status != 2 else []:
            findings.append(f"{where}: {p}: {command}")
        if block.parse_only or skip:
            parsed += 1
            continue
        ran += 1
        try:
            r = subprocess.run(["bash", "-c", "exec 2>&1; stdbuf -oL -eL bash -c " + shlex.quote(command)],
                               cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            findings.append(f"{where}: ran over {timeout} s: {command}")
            continue
        actual = [l.rstrip() for l in r.stdout.splitlines()]
        while actual and actual[-1] == "":
            actual.pop()
        if r.returncode != status:
            findings.append(f"{where}: exit {r.returncode}, the docs show {status}: {command}\n" +
                            "\n".join("    | " + l for l in actual[-8:]))
        elif not matches(shown, actual):
            findings.append(f"{where}: the output differs from the docs': {command}\n" +
                            "\n".join("    shown | " + l for l in shown) + "\n" +
                            "\n".join("    run   | " + l for l in actual))
    return ran, parsed


def shown_path(path):
    """A document's name in findings: relative to the repository when it is in it."""
    try:
        return path.relative_to(ROOT)
    except ValueError:
        return path


def check_file(path, trivox, python_path, findings, timeout):
    blocks = blocks_of(path)
    rel = shown_path(path)
    ran = parsed = 0
    with tempfile.TemporaryDirectory(prefix="trivox-docs-") as tmp:
        cwd, env = sandbox(pathlib.Path(tmp), trivox, python_path)
        python_blocks = [b for b in blocks if b.lang in PYTHON_LANGS]
        for b in blocks:
            if b.lang in PYTHON_LANGS:
                continue
            if b.transcript():
                r, p = run_transcript(b, trivox, cwd, env, findings, timeout)
                ran, parsed = ran + r, parsed + p
                continue
            for k, line in enumerate(b.lines):
                if COMMAND_LINE.search(line):
                    parsed += 1
                    command = re.sub(r"(?<=\S) {2,}.*$", "", line)  # a synopsis's description
                    for p in parse_problems(trivox, command):
                        findings.append(f"{rel}:{b.line + 1 + k}: {p}: {line.strip()}")
        # After the file's commands, which may write what its Python reads.
        run_python(python_blocks, rel, cwd, env, python_path is not None, findings, 4 * timeout)
        runs = sum(1 for b in python_blocks if python_path and not b.parse_only)
        ran, parsed = ran + runs, parsed + len(python_blocks) - runs
    return ran, parsed


SELF_TEST = '''# A page with one of each finding

<!-- docs-check: parse-only an input not given -->
```
$ trivox slice nowhere.json -o out/x --no-such-option
```

```
$ trivox --version | head -1
trivox 0.0.0
$ echo "took 1.5 s"
took ~2 s
$ printf 'a\\nb\\nc\\n'
a
...
$ false
$ trivox info --colour x.itd
The following argument was not expected: --colour
...
exit 2
```

```sh
trivox vaildate scene.json
TRIVOX_SIMD=sse4 build/release/bin/trivox info --bogus x.itd
trivox cluster slurm s.json -o d --shards 2 --partition p --sharts 2
trivox: error: x.itd: an output line where trivox says what it does
```

```pycon
>>> 6 * 7
41
```

```python
undefined_name
```
'''


def self_test(trivox, python_path):
    """Checks that the checker finds what it should on a page made to hold one of each."""
    with tempfile.TemporaryDirectory(prefix="trivox-docs-self-") as tmp:
        page = pathlib.Path(tmp) / "page.md"
        page.write_text(SELF_TEST)
        findings = []
        ran, parsed = check_file(page, trivox, python_path, findings, 30)
    text = "\n".join(findings)
    expected = ["has no option --no-such-option", "the output differs from the docs': trivox --version",
                "exit 1, the docs show 0: false", "'vaildate' is no subcommand",
                "trivox info has no option --bogus", "trivox cluster slurm has no option --sharts"]
    if python_path:  # without the module the Python blocks are only compiled
        expected += ["Expected:\n    |     41", "NameError"]
    missing = [e for e in expected if e not in text]
    unexpected = [f for f in findings if "echo" in f or "printf" in f or "--colour" in f]
    if missing or unexpected or len(findings) != len(expected):
        print(text)
        print(f"check_docs self-test: FAILED: missing {missing}, unexpected {unexpected}")
        return 1
    print(f"check_docs self-test: ok ({len(findings)} findings as planted, {ran} run, {parsed} parsed)")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--trivox", default=str(ROOT / "build" / "release" / "bin" / "trivox"))
    ap.add_argument("--python-path", help="the build's python/ folder (without it, Python blocks are compiled only)")
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds one command may take")
    ap.add_argument("--self-test", action="store_true", help="check the checker on a page of planted faults")
    ap.add_argument("files", nargs="*", help="documents to check (default: all)")
    a = ap.parse_args()
    if a.self_test:
        return self_test(a.trivox, a.python_path)
    files = [pathlib.Path(f).resolve() for f in a.files] or (
        [ROOT / "README.md", ROOT / "examples" / "README.md"] + sorted((ROOT / "docs").glob("*.md")))
    findings = []
    ran = parsed = 0
    for f in files:
        r, p = check_file(f, a.trivox, a.python_path, findings, a.timeout)
        ran += r
        parsed += p
    for f in findings:
        print(f)
    print(f"check_docs: {ran} commands and Python blocks run and compared, {parsed} parsed or compiled, "
          f"{len(findings)} findings")
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
