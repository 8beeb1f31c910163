#!/usr/bin/python3
"""No document or comment names a file that is not in the repository.

    /usr/bin/python3 tests/check_doc_paths.py [REPO_ROOT]

Scans every Markdown file, the comments of every C++ file (.h, .cpp: // and /* */, not string
literals) and the scripts (Python, shell, CMake; their whole text, usage and docstrings included)
for repository paths: words that begin with one of the top-level folders below and end
in a file extension or a '/', and, in Markdown, the targets of relative links. A path with * or
{a,b} must match at least one file. Exit 1, listing file:line: path, for any that names nothing.

"The repository" is what git tracks plus new files it does not ignore, so an output a command
writes into the tree (and .gitignore hides) does not count as present; without git (a source
tarball) it is the files on disk, build folders excluded. Placeholders (integrators/<name>.cpp,
scenes/$s) are not paths, nor is git's REV:PATH (a file on another branch); both are skipped.
Standard library only.
"""
import fnmatch
import os
import re
import subprocess
import sys

ROOTS = ("core", "renderer", "docs", "scenes", "tests", "cmake", "integrators")

# Files that documents name but the repository does not hold, because a command makes them. Each
# entry is a path and why it is absent; keep this to generated files.
ALLOWED = {
    "scenes/dense/dense.obj": "made by `pt gen dense` (1.3 M triangles, too large to commit; .gitignore)",
    "scenes/scan/scan.obj": "made by `pt gen scan` (1 M triangles, too large to commit; .gitignore)",
}

SCRIPT_ENDINGS = (".py", ".sh", ".cmake", "CMakeLists.txt")
SCRIPTS = {"renderer/farm/pt-slurm", ".ci/run"}  # scripts without an extension

# A repository path: a top-level folder, then path characters. Not inside a longer word or path
# (build-asan/tests/..., /shared/docs/...), hence the look-behind.
PATH_RE = re.compile(r"(?<![\w./\-~$])((?:%s)/[\w./+\-*{},<>$]*)" % "|".join(ROOTS))
# A Markdown link or image target: ](target) or ](target "title").
LINK_RE = re.compile(r"\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
EXT_RE = re.compile(r"\.[A-Za-z0-9]+$")


def repo_files(root):
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "--cached", "--others", "--exclude-standard", "-z"],
                             capture_output=True, check=True).stdout.decode("utf-8", "replace")
        files = {f for f in out.split("\0") if f and os.path.lexists(os.path.join(root, f))}
        if files:
            return files
    except (OSError, subprocess.CalledProcessError):
        pass
    files = set()
    for d, dirs, names in os.walk(root):
        rel = os.path.relpath(d, root)
        dirs[:] = [x for x in dirs if not x.startswith((".git", "build")) and x != "__pycache__"]
        for n in names:
            files.add(n if rel == "." else os.path.join(rel, n).replace(os.sep, "/"))
    return files


def folders_of(files):
    dirs = set()
    for f in files:
        parts = f.split("/")[:-1]
        for i in range(1, len(parts) + 1):
            dirs.add("/".join(parts[:i]))
    return dirs


def expand_braces(pattern):
    m = re.search(r"\{([^{}]*)\}", pattern)
    if not m:
        return [pattern]
    out = []
    for alt in m.group(1).split(","):
        out += expand_braces(pattern[:m.start()] + alt + pattern[m.end():])
    return out


def cpp_comments(text):
    """(line number, comment text) for each comment line of a C++ source, skipping literals."""
    out = []
    i, n, line = 0, len(text), 1
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
            i += 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append((line, text[i + 2:j]))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j
            for k, part in enumerate(text[i + 2:j].split("\n")):
                out.append((line + k, part))
            line += text.count("\n", i, j)
            i = j + 2
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            open_paren = text.find("(", i + 2)
            delim = text[i + 2:open_paren]
            end = text.find(")" + delim + '"', open_paren)
            end = n if end < 0 else end + len(delim) + 2
            line += text.count("\n", i, end)
            i = end
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            i = j + 1
        else:
            i += 1
    return out


def clean(token):
    token = token.rstrip(".,:;")
    # A closing parenthesis or brace belongs to the sentence, not the path, unless it closes one.
    while token and token[-1] in ")}" and token.count("{") < token.count("}") + (token[-1] == ")"):
        token = token[:-1].rstrip(".,:;")
    return token


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
    files = repo_files(root)
    dirs = folders_of(files)

    def exists(path):
        path = os.path.normpath(path).replace(os.sep, "/")
        if path in ALLOWED:
            return True
        if path.endswith("/"):
            path = path[:-1]
        if any(ch in path for ch in "*?{"):
            return any(fnmatch.filter(files | dirs, p) for p in expand_braces(path))
        return path in files or path in dirs

    problems = []

    def check(source, line, text, markdown):
        for m in PATH_RE.finditer(text):
            token = clean(m.group(1))
            if any(ch in token for ch in "<>$"):
                continue  # a placeholder: integrators/<name>.cpp, scenes/$s
            if re.search(r"[\w\-]:$", text[:m.start()]):
                continue  # git's REV:PATH, a file of another branch (wip/lights:core/scene/lights/)
            if not (token.endswith("/") or EXT_RE.search(token) or any(ch in token for ch in "*{")):
                continue  # a word such as "renderer/bench" in prose is too ambiguous to require
            if not exists(token):
                problems.append("%s:%d: %s" % (source, line, token))
        if markdown:
            for m in LINK_RE.finditer(text):
                target = m.group(1).split("#")[0]
                if not target or re.match(r"^[a-z]+:", target) or target.startswith("/"):
                    continue
                rel = os.path.normpath(os.path.join(os.path.dirname(source), target)).replace(os.sep, "/")
                if not exists(rel):
                    problems.append("%s:%d: %s (link)" % (source, line, target))

    for f in sorted(files):
        markdown = f.endswith(".md")
        cpp = f.endswith((".h", ".cpp"))
        script = f.endswith(SCRIPT_ENDINGS) or f in SCRIPTS
        if not (markdown or cpp or script) or f == "tests/check_doc_paths.py":
            continue  # this file's own examples are paths that do not exist, on purpose
        with open(os.path.join(root, f), encoding="utf-8", errors="replace") as fh:
            text = fh.read()
        if markdown or script:
            for number, line in enumerate(text.split("\n"), 1):
                check(f, number, line, markdown)
        else:
            for number, comment in cpp_comments(text):
                check(f, number, comment, False)

    for p in problems:
        print(p)
    if problems:
        print("check_doc_paths: %d path(s) name nothing in the repository (allowed generated files: %s)"
              % (len(problems), ", ".join(sorted(ALLOWED))), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
