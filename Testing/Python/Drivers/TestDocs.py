"""Checks that the README and the pages under docs/ say what the tree does: every relative link
points to a file (and section) that exists, the README keeps its two set-up commands and stays
short, the code blocks marked `<!-- test: run -->` run, and the other blocks name only files,
`./rgmc` verbs and command-line options that exist.

  python3 TestDocs.py --source DIR --build-dir DIR --workdir DIR [--xvfb-run xvfb-run] [--pvbatch pvbatch]

Runnable blocks are run as a user runs them from a checkout: in a scratch directory that links
every top-level entry of the source tree and `build` to the build directory. A block marked
`<!-- test: run after PAGE#SECTION -->` continues the first Python block of that section, which
is run before it. The examples name the plugin of ParaView 5.11 (Debian 12); on another release
`paraview-5.11` is read as the build's own version.
"""

import argparse
import glob
import os
import re
import shlex
import shutil
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [os.path.join(HERE, "..", "Modules"), os.path.join(HERE, "..")]
from rgmc_testing import check, finish, run, xvfb_run  # noqa: E402

README_MAX_LINES = 300
# The evaluation page holds the figures, not the history of how they were reached.
EVALUATION_MAX_LINES = 400
# The README's set-up commands, exactly as a newcomer types them.
SETUP_COMMANDS = [
    "./rgmc demo    # install what is missing, build, read a real head CT, extract its skull "
    "on 2 MPI ranks",
    "./rgmc test    # install what is missing, build, run the whole test suite",
]
EXAMPLES_PARAVIEW = "paraview-5.11"
FENCE = re.compile(r"^( *)```(\S*)\s*$")
MARKER = re.compile(r"^<!-- test: run(?: after (\S+))? -->$")
HEADING = re.compile(r"^(#{1,6}) +(.*?) *#*$")
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")
CODE_SPAN = re.compile(r"`([^`\n]+)`")
# A path in the source tree, as the pages write it (not one under build/ or an absolute one).
TREE_PATH = re.compile(
    r"(?<![\w./$~-])((?:\.ci|CMake|Plugin|Filters|XML|Scripts|Benchmark|Testing|docs)/[\w./-]*)")
# The scripts whose options the pages use, by how a command line names them.
SCRIPTS = {
    "Scripts/rgmc_pipeline.py": "Scripts/rgmc_pipeline.py",
    "Scripts/rgmc_dicom_series.py": "Scripts/rgmc_dicom_series.py",
    "Scripts/rgmc_evaluate.py": "Scripts/rgmc_evaluate.py",
    "./rgmc run": "Scripts/rgmc_pipeline.py",
    "./rgmc evaluate": "Scripts/rgmc_evaluate.py",
    "./rgmc matrix": "Scripts/rgmc-matrix",
    "./rgmc test": "rgmc",
}
# Sections whose code spans `--option` are the options of one script (its option table).
OPTION_SECTIONS = {
    ("docs/using.md", "the-pipeline-command"): "Scripts/rgmc_pipeline.py",
    ("docs/readers.md", "writing-a-dicom-series-the-generator"): "Scripts/rgmc_dicom_series.py",
    ("docs/evaluation.md", None): "Scripts/rgmc_evaluate.py",
}


def slug(heading):
    """The anchor GitHub gives a heading."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


class Page:
    """A Markdown page: its lines outside code blocks (with the section each is in), its code
    blocks, and its section anchors."""

    def __init__(self, source, name):
        self.name = name
        self.path = os.path.join(source, name)
        with open(self.path, encoding="utf-8") as f:
            self.lines = f.read().split("\n")
        self.prose = []  # (section, line)
        self.blocks = []  # dicts: language, text, marker, section, line
        self.anchors = set()
        section, fence = None, None
        for number, line in enumerate(self.lines, 1):
            match = FENCE.match(line)
            if fence is not None:
                if match and len(match.group(1)) <= len(fence["indent"]) and not match.group(2):
                    fence["text"] = "\n".join(fence.pop("body")) + "\n"
                    self.blocks.append(fence)
                    fence = None
                else:
                    indent = fence["indent"]
                    fence["body"].append(line[len(indent):] if line.startswith(indent) else line)
                continue
            if match:
                previous = self.lines[number - 2].strip() if number > 1 else ""
                marker = MARKER.match(previous)
                fence = {"indent": match.group(1), "language": match.group(2), "body": [], "line": number,
                         "section": section, "marker": marker and (marker.group(1) or "run")}
                continue
            heading = HEADING.match(line)
            if heading:
                section = slug(heading.group(2))
                self.anchors.add(section)
            self.prose.append((section, line))
        check(fence is None, "%s: the code block at line %s is closed" % (name, fence and fence["line"]))

    def spans(self):
        """(section, text) of every code span outside code blocks."""
        return [(section, span) for section, line in self.prose for span in CODE_SPAN.findall(line)]


def check_links(source, pages):
    """(a) Every relative link of every page points to a file, and its #anchor to a heading."""
    by_path = {os.path.realpath(page.path): page for page in pages}
    for page in pages:
        text = "\n".join(CODE_SPAN.sub("", line) for _, line in page.prose)
        for target in LINK.findall(text):
            if re.match(r"^[a-z]+:", target):
                continue
            path, _, anchor = target.partition("#")
            resolved = os.path.realpath(os.path.join(os.path.dirname(page.path), path)) if path else \
                os.path.realpath(page.path)
            inside = resolved.startswith(os.path.realpath(source) + os.sep)
            check(inside and os.path.exists(resolved),
                  "%s: the link %s points to a file of the tree" % (page.name, target))
            if anchor and resolved in by_path:
                check(anchor in by_path[resolved].anchors,
                      "%s: the link %s points to a section" % (page.name, target))


def check_readme(readme, docs):
    """(b) The README keeps the two set-up commands and its length; every page links back to it."""
    count = len(readme.lines) - (readme.lines[-1] == "")
    check(count <= README_MAX_LINES, "README.md has at most %d lines (it has %d)" % (README_MAX_LINES, count))
    setup = [b for b in readme.blocks
             if b["language"] == "sh" and b["text"].split("\n")[:2] == SETUP_COMMANDS]
    check(len(setup) == 1, "README.md shows the two set-up commands: %s" % " / ".join(SETUP_COMMANDS))
    for page in docs:
        check(any("](../README.md)" in line for line in page.lines[:6]),
              "%s links back to the README at its top" % page.name)
        if page.name == os.path.join("docs", "evaluation.md"):
            count = len(page.lines) - (page.lines[-1] == "")
            check(count <= EVALUATION_MAX_LINES, "docs/evaluation.md has at most %d lines (it has %d)"
                  % (EVALUATION_MAX_LINES, count))


def accepted_options(source, script):
    """The command-line options `script` accepts, read from its source: its argparse calls, or
    for a shell script every `--word` it spells."""
    with open(os.path.join(source, script), encoding="utf-8") as f:
        text = f.read()
    if script.endswith(".py"):
        options = set(re.findall(r"add_argument\(\s*\"(--[\w-]+)\"", text))
        options |= set(re.findall(r"add_argument\(\s*\"-\w\",\s*\"(--[\w-]+)\"", text))
        return options | {"--help"}
    return set(re.findall(r"(?<![\w-])(--[\w-]+)", text))


def rgmc_verbs(source):
    """The verbs of ./rgmc: the patterns of its last `case "$cmd" in`."""
    with open(os.path.join(source, "rgmc"), encoding="utf-8") as f:
        text = f.read()
    body = text[text.rindex('case "$cmd" in'):]
    body = body[:body.index("esac")]
    return set(re.findall(r"^\s*([a-z][\w-]*)\)", body, re.M))


def command_lines(text):
    """The command lines of a shell text: continuations joined, comments dropped."""
    joined = re.sub(r"\\\n", " ", text)
    for line in joined.split("\n"):
        try:
            yield shlex.split(line, comments=True)
        except ValueError:
            yield line.split()


def check_command(source, where, words, verbs, options):
    """The `./rgmc` verb and the script options one command line uses."""
    for i, word in enumerate(words):
        if word == "./rgmc" and i + 1 < len(words) and not words[i + 1].startswith("-"):
            check(words[i + 1] in verbs, "%s: `./rgmc %s` is a verb of ./rgmc" % (where, words[i + 1]))
            key = "./rgmc " + words[i + 1]
        elif word in SCRIPTS:
            key = word
        else:
            continue
        script = SCRIPTS.get(key)
        if script is None:
            return
        if not os.path.exists(os.path.join(source, script)):
            return  # the missing file is reported by check_paths
        for arg in words[i + 1:]:
            name = arg.split("=")[0]
            if name.startswith("--") and name != "--":
                check(name in options(script), "%s: %s accepts %s" % (where, script, name))
        return


def check_named_things(source, pages):
    """(c) What the code blocks and code spans name: files of the tree, ./rgmc verbs, options."""
    verbs = rgmc_verbs(source)
    cache = {}

    def options(script):
        if script not in cache:
            cache[script] = accepted_options(source, script)
        return cache[script]

    for page in pages:
        texts = [("%s line %d" % (page.name, b["line"]), b["text"], b["language"]) for b in page.blocks]
        texts += [("%s `%s`" % (page.name, span), span, "span") for _, span in page.spans()]
        for where, text, language in texts:
            for path in TREE_PATH.findall(text):
                path = path.rstrip(".,")
                check(os.path.exists(os.path.join(source, path)), "%s: %s exists" % (where, path))
            if language in ("sh", "span"):
                for words in command_lines(text):
                    check_command(source, where, words, verbs, options)
        for section, span in page.spans():
            script = OPTION_SECTIONS.get((page.name, section)) or OPTION_SECTIONS.get((page.name, None))
            if script and span.startswith("--"):
                name = re.split(r"[ =]", span)[0]
                check(name in options(script), "%s: `%s` is an option of %s" % (page.name, span, script))


def scratch_checkout(source, build_dir, workdir):
    """A new directory that looks like a checkout with its build in `build/`, for running blocks
    (what an earlier run wrote is removed; the links are removed, not followed)."""
    scratch = os.path.join(workdir, "checkout")
    if os.path.lexists(scratch):
        shutil.rmtree(scratch)
    os.makedirs(scratch)
    for name in os.listdir(source):
        if name not in (".git", "build"):
            os.symlink(os.path.join(source, name), os.path.join(scratch, name))
    os.symlink(build_dir, os.path.join(scratch, "build"))
    return scratch


def first_python_block(pages, page, reference):
    """The first Python block of the section PAGE#SECTION names (a link from `page`)."""
    path, _, section = reference.partition("#")
    name = os.path.normpath(os.path.join(os.path.dirname(page.name), path)) if path else page.name
    for page in pages:
        if page.name == name:
            for block in page.blocks:
                if block["section"] == section and block["language"] == "python":
                    return block
    return None


def run_blocks(args, pages):
    """Runs every block marked runnable (each distinct block once)."""
    scratch = scratch_checkout(args.source, args.build_dir, args.workdir)
    built = sorted(glob.glob(os.path.join(args.build_dir, "lib", "paraview-*")))
    version = os.path.basename(built[0]) if built else EXAMPLES_PARAVIEW
    env = dict(os.environ, RGMC_BUILD_DIR=os.path.join(scratch, "build"))
    os.chdir(scratch)
    done = set()
    for page in pages:
        for block in page.blocks:
            if not block["marker"]:
                continue
            where = "%s line %d" % (page.name, block["line"])
            text = block["text"]
            if block["marker"] != "run":
                before = first_python_block(pages, page, block["marker"])
                check(before is not None, "%s: the block it continues (%s) exists" % (where, block["marker"]))
                text = (before["text"] if before else "") + text
            text = text.replace(EXAMPLES_PARAVIEW, version)
            if (block["language"], text) in done:
                continue
            done.add((block["language"], text))
            script = os.path.join(args.workdir, "block-%d.%s" % (len(done), block["language"]))
            with open(script, "w", encoding="utf-8") as f:
                f.write(text)
            if block["language"] == "sh":
                command = ["bash", "-e", script]
            elif block["language"] == "python":
                command = [args.pvbatch, script]
                if args.xvfb_run and not os.environ.get("DISPLAY"):
                    command = xvfb_run(args.xvfb_run, command)
            else:
                check(False, "%s: a runnable block is sh or python, not %r" % (where, block["language"]))
                continue
            print("%s:\n%s" % (where, text), flush=True)
            result = run(command, env=env, tail=3000)
            check(result.returncode == 0, "%s runs (exit status %d)" % (where, result.returncode))


def main():
    parser = argparse.ArgumentParser()
    for name in ("--source", "--build-dir", "--workdir"):
        parser.add_argument(name, required=True)
    parser.add_argument("--pvbatch", default="pvbatch")
    parser.add_argument("--xvfb-run")
    parser.add_argument("--no-run", action="store_true", help="check the pages without running blocks")
    args = parser.parse_args()
    for name in ("source", "build_dir", "workdir"):
        setattr(args, name, os.path.abspath(getattr(args, name)))
    os.makedirs(args.workdir, exist_ok=True)

    readme = Page(args.source, "README.md")
    docs = [Page(args.source, os.path.relpath(p, args.source))
            for p in sorted(glob.glob(os.path.join(args.source, "docs", "*.md")))]
    check(len(docs) > 0, "docs/ holds pages")
    contributing = Page(args.source, "CONTRIBUTING.md")
    pages = [readme, contributing] + docs
    check_links(args.source, pages)
    check_readme(readme, docs)
    check_named_things(args.source, pages)
    if not args.no_run:
        run_blocks(args, pages)

    return finish("TestDocs")


sys.exit(main())
