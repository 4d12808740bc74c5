#!/usr/bin/env python3
"""Checks that the tree tells the truth about itself (the code-health rules of README "Testing").

  1. No function longer than 150 lines (from the line of its opening brace to that of its closing
     brace, lambdas counted in the function that holds them) in core/, server/, client/, proto/,
     bench/ and fuzz/. Tests are exempt: a TEST body is a script, not an abstraction.
  2. Every repository path named in a tracked source, script or doc exists (a path is a word that
     starts with one of the top-level folders, e.g. `core/plan/src/route.cc` or `docs/PLANNING.md`;
     globs like `tests/core/*/*_test.cc` are matched as globs; `build/...` and `../shared/...` are
     outputs and data, not checked).
  3. Every public header has a mirrored test (core/<layer>/include/vc/<layer>/<x>.h ->
     tests/core/<layer>/<x>_test.cc; server/include/vc/server/<x>.h -> tests/server/<x>_test.cc;
     client/ -> tests/client/; proto/include/vc/wire/<x>.h -> tests/proto/<x>_test.cc) or a line in
     scripts/header-test-exemptions.txt saying why not; and every tests/**/<x>_test.cc is compiled into
     a test executable (named in a tests/**/CMakeLists.txt).

The function scanner strips comments, strings and raw strings, then matches braces; a brace opens a
function body when the text before it ends in a parameter list (with qualifiers, a trailing return
type or a constructor's initialiser list) and is not an if/for/while/switch/catch. It relies on the
code being clang-formatted, which scripts/test.sh checks first. A real C++ parser (clang-tidy's
readability-function-size over compile_commands.json) gives the same list but needs each translation
unit parsed with its gRPC headers: minutes on two cores, against well under a second here.
Usage: scripts/check-code-health.py [--max-lines N] [--list]   (--list: print every function's length)
Exit 1 with one line per problem.
"""
import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
MAX_LINES = 150
CODE_DIRS = ("core/", "server/", "client/", "proto/", "bench/", "fuzz/")
TOP = ("core", "server", "client", "proto", "bench", "fuzz", "tests", "docs", "scripts", "deploy", "cmake", ".ci")
INCLUDE = re.compile(r'\s*#\s*include\b')
EXEMPTIONS = ROOT / "scripts" / "header-test-exemptions.txt"


def tracked():
    out = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    return [p for p in out.splitlines() if (ROOT / p).is_file()]


def blank(text):
    return re.sub(r"[^\n]", " ", text)


LITERAL_PREFIXES = ("", "u", "U", "L", "u8")


def word_before(src, i):
    """The identifier or number that ends just before src[i] ("" when none)."""
    j = i
    while j > 0 and (src[j - 1].isalnum() or src[j - 1] == "_"):
        j -= 1
    return src[j:i]


def strip_code(src):
    """src with comments, string and character literals blanked out (newlines kept). Literal
    prefixes (u8"", L'x', LR"(...)") are literals too; a ' inside a number (1'000) is not."""
    out, i, n = [], 0, len(src)
    while i < n:
        if src.startswith("//", i):
            j = src.find("\n", i)
            j = n if j < 0 else j
        elif src.startswith("/*", i):
            j = src.find("*/", i + 2)
            j = n if j < 0 else j + 2
        elif src.startswith('R"', i) and word_before(src, i) in LITERAL_PREFIXES:
            m = re.match(r'R"([^(\s]*)\(', src[i:])
            end = src.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
        elif src[i] in "\"'" and word_before(src, i) in LITERAL_PREFIXES:
            quote, j = src[i], i + 1
            while j < n and src[j] != quote and src[j] != "\n":
                j += 2 if src[j] == "\\" else 1
            j += 1
        else:
            out.append(src[i])
            i += 1
            continue
        out.append(blank(src[i:j]))
        i = j
    return "".join(out)


# What may stand between a function's parameter list and its body: qualifiers, a trailing return
# type, a requires clause, a macro (VC_NOEXCEPT), `try`, and a constructor's initialiser list.
FUNCTION_HEAD = re.compile(
    r"\)\s*((const|override|final|noexcept|mutable|try|&&?|->\s*[\w:<>,\s*&]+|\[\[[\w:]+\]\]|[A-Z][A-Z0-9_]+"
    r"|requires\s+[^;{}]+?)\s*)*(:[^;]*)?$")
LAMBDA_HEAD = re.compile(r"\[[^\[\]]*\]\s*(mutable\s*)?$")  # [] { ... } without a parameter list
# A braced member initialiser (`: a_(x), b_{y}`): the brace follows a name in the initialiser list.
MEMBER_INIT = re.compile(r"\)\s*(noexcept\s*)?:[^;]*[\w>]$")
CONTROL = re.compile(r"\b(if|for|while|switch|catch|namespace|class|struct|enum|union)\b[^()]*(\(|$)")


def functions(path):
    """(name, first line, lines) of every function defined in the file, outermost only."""
    text = strip_code((ROOT / path).read_text(errors="replace"))
    stack, last, found = [], 0, []
    for m in re.finditer(r"[{};]", text):
        pos = m.start()
        if m.group() == "{":
            head = " ".join(text[last:pos].split())
            inside = any(kind == "fn" for kind, _, _ in stack)
            if not inside and not CONTROL.match(head) and MEMBER_INIT.search(head):
                stack.append(("init", 0, ""))  # the head goes on to the body's brace
                continue
            is_fn = not inside and not CONTROL.match(head) and (FUNCTION_HEAD.search(head) or LAMBDA_HEAD.search(head))
            names = re.findall(r"([~\w:]+)\s*\(", head)
            stack.append(("fn" if is_fn else "block", text.count("\n", 0, pos) + 1, names[0] if names else head[:40]))
        elif m.group() == "}" and stack:
            kind, line, name = stack.pop()
            if kind == "init":
                continue
            if kind == "fn":
                found.append((name, line, text.count("\n", 0, pos) + 1 - line + 1))
        last = pos + 1
    return found


# A path from the repository root, bare or after "./" (not inside $BIN/... or build/...).
PATH = re.compile(r"(?:(?<![\w./-])|(?<=(?<![\w./-])\./))((?:" + "|".join(re.escape(t) for t in TOP) + r")/[\w./*{}-]*[\w*}])")


def path_exists(ref, files, dirs):
    ref = ref.rstrip(".")
    if "{" in ref:  # brace lists like core/{scene,plan}/: not expanded; checked by their prefix
        ref = ref.split("{")[0].rstrip("/")
        return not ref or ref in dirs or ref in files
    if "*" in ref:
        rx = re.compile("^" + re.escape(ref).replace(r"\*", "[^/]*") + "$")
        return any(rx.match(f) for f in files) or any(rx.match(d) for d in dirs)
    return ref in files or ref.rstrip("/") in dirs


def main():
    max_lines = MAX_LINES
    if "--max-lines" in sys.argv:
        max_lines = int(sys.argv[sys.argv.index("--max-lines") + 1])
    files = tracked()
    fileset = set(files)
    dirs = {str(pathlib.PurePosixPath(f).parents[i]) for f in files for i in range(len(pathlib.PurePosixPath(f).parents) - 1)}
    problems, longest = [], []

    for f in files:
        if f.startswith(CODE_DIRS) and f.endswith((".h", ".cc")):
            for name, line, lines in functions(f):
                longest.append((lines, f"{f}:{line} {name}"))
                if lines > max_lines:
                    problems.append(f"{f}:{line}: function {name} spans {lines} lines (at most {max_lines}); split it")

    for f in files:
        if not f.endswith((".h", ".cc", ".md", ".sh", ".py", ".txt", ".cmake", ".proto", ".yaml", ".yml")) and f not in (
                "Dockerfile", ".ci/run"):
            continue
        if f == "scripts/check_code_health_test.py":  # names missing paths on purpose
            continue
        for n, text in enumerate((ROOT / f).read_text(errors="replace").splitlines(), 1):
            if INCLUDE.match(text):  # the compiler checks #include lines
                continue
            for ref in PATH.findall(text):
                if not path_exists(ref, fileset, dirs):
                    problems.append(f"{f}:{n}: names {ref}, which is not in the repository")

    exempt = {}
    if EXEMPTIONS.exists():
        for n, line in enumerate(EXEMPTIONS.read_text().splitlines(), 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            header, _, why = line.partition(" ")
            if not why.strip():
                problems.append(f"{EXEMPTIONS.relative_to(ROOT)}:{n}: {header} is exempt without a reason")
            if header not in fileset:
                problems.append(f"{EXEMPTIONS.relative_to(ROOT)}:{n}: {header} is not a tracked header")
            exempt[header] = why.strip()
    for f in files:
        m = re.match(r"(core/(\w+)/include/vc/\w+|server/include/vc/server|client/include/vc/client|proto/include/vc/wire)/(\w+)\.h$", f)
        if not m:
            continue
        folder = {"server": "tests/server", "client": "tests/client", "proto": "tests/proto"}.get(f.split("/")[0])
        folder = folder or f"tests/core/{m.group(2)}"
        test = f"{folder}/{m.group(3)}_test.cc"
        if not any(t == test or (t.startswith(folder + "/") and t.endswith("/" + m.group(3) + "_test.cc")) for t in fileset):
            if f not in exempt:
                problems.append(f"{f}: no mirrored test ({test}) and no line in scripts/header-test-exemptions.txt")
        elif f in exempt:
            problems.append(f"scripts/header-test-exemptions.txt: {f} has a test ({test}); drop its exemption")

    cmake_text = "\n".join((ROOT / f).read_text() for f in files if f.startswith("tests/") and f.endswith("CMakeLists.txt"))
    for f in files:
        if f.startswith("tests/") and f.endswith("_test.cc") and not re.search(
                r"(^|[\s/])" + re.escape(pathlib.PurePosixPath(f).name) + r"(\s|\))", cmake_text):
            problems.append(f"{f}: a test file in no test executable (tests/**/CMakeLists.txt names no {pathlib.PurePosixPath(f).name})")

    if "--list" in sys.argv:
        for lines, where in sorted(longest, reverse=True)[:30]:
            print(f"{lines:5d} {where}")
    for p in problems:
        print(p)
    if problems:
        return 1
    print(f"check-code-health: {len(longest)} functions, the longest {max(longest)[0]} lines (at most {max_lines}); "
          f"every repository path named exists; every public header has a test or a written exemption")
    return 0


if __name__ == "__main__":
    sys.exit(main())
