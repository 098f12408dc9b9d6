"""The house's sizes hold (CONTRIBUTING.md): no product function over 80 lines and no product file
over 1 200 (Scripts/rgmc-code-shape). First the check is shown to catch what it must: a tree
with an 81-line function, an 81-line lambda-holding function and a 1 201-line file fails and
names them, while an 80-line function and a 1 200-line file pass.

  python3 TestCodeShape.py --source DIR --workdir DIR
"""

import argparse
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Modules"))
from rgmc_testing import check, finish  # noqa: E402


def function(name, lines, indent=""):
    """A clang-formatted function of exactly `lines` lines."""
    body = ["%s  x += %d;" % (indent, i) for i in range(lines - 3)]
    return ["%svoid %s(int& x)" % (indent, name), indent + "{"] + body + [indent + "}"]


def lambda_function(name, lines):
    """A function whose length is mostly one lambda, as a ranks.Step call writes one."""
    inner = ["      x += %d;" % i for i in range(lines - 7)]
    return (["void %s(int& x)" % name, "{", "  auto step = [&]()", "    {"] + inner +
            ["    };", "  step();", "}"])


def shape(root, script):
    run = subprocess.run([sys.executable, script, root], capture_output=True, text=True)
    return run.returncode, run.stdout


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--source", required=True)
    parser.add_argument("--workdir", required=True)
    args = parser.parse_args()
    script = os.path.join(args.source, "Scripts", "rgmc-code-shape")

    tree = os.path.join(args.workdir, "tree")
    shutil.rmtree(tree, ignore_errors=True)
    os.makedirs(os.path.join(tree, "Filters"))
    os.makedirs(os.path.join(tree, "Plugin"))
    with open(os.path.join(tree, "Filters", "long.cxx"), "w") as f:
        f.write("\n".join(function("TooLong", 81) + function("JustRight", 80) +
                          lambda_function("LongLambda", 81) +
                          ["namespace n", "{", "struct S", "{"] + function("Member", 85, "  ") +
                          ["};", "}"]) + "\n")
    with open(os.path.join(tree, "Plugin", "big.h"), "w") as f:
        f.write("\n".join("// line %d" % i for i in range(1201)) + "\n")
    with open(os.path.join(tree, "Plugin", "fits.h"), "w") as f:
        f.write("\n".join("// line %d" % i for i in range(1200)) + "\n")
    status, out = shape(tree, script)
    check(status == 1, "a tree over the limits fails the check (exit %d)" % status)
    for name in ("TooLong", "LongLambda", "Member", "big.h"):
        check(name in out, "the check names %s:\n%s" % (name, out))
    for name in ("JustRight", "fits.h"):
        check(name not in out, "the check leaves %s alone:\n%s" % (name, out))

    status, out = shape(args.source, script)
    print(out)
    check(status == 0, "the product keeps its sizes:\n%s" % out)
    return finish("TestCodeShape")


sys.exit(main())
