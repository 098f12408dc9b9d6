"""What the Python tests share: the list of failed checks, running a command with its output
shown in the test's log, how to start MPI and a private X server on every Debian release, and
where the scripts that run inside ParaView are (Testing/Python/InParaView)."""

import argparse
import glob
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", "Scripts"))
import rgmc_common  # noqa: E402

IN_PARAVIEW = os.path.normpath(os.path.join(HERE, "..", "InParaView"))

# Xvfb resets whenever its last client disconnects; an MPI rank that connects during the reset
# aborts with "bad X server connection". -noreset keeps the server up for the whole command.
XVFB_SERVER_ARGS = "-screen 0 1280x1024x24 -noreset"

failures = []


def in_paraview(name):
    """The path of `name`, a script that pvbatch, pvpython or the GUI runs for a test."""
    return os.path.join(IN_PARAVIEW, name)


def linkage_arguments():
    """The arguments of the tests that read the plugin's shared objects (TestNoMPI, TestOwnCalls):
    --readelf, --nm, --plugin-dir, --control, and --module (a library of the plugin kept outside
    its directory, repeated); then the objects, real paths, sorted. None (having said why) when
    RGMarchingCubes.so is not among them."""
    parser = argparse.ArgumentParser()
    for name in ("--readelf", "--nm", "--plugin-dir", "--control"):
        parser.add_argument(name, required=True)
    parser.add_argument("--module", action="append", default=[],
                        help="a library of the plugin kept outside its directory")
    args = parser.parse_args()
    found = glob.glob(os.path.join(args.plugin_dir, "*.so*")) + args.module
    objects = sorted(set(os.path.realpath(p) for p in found if os.path.isfile(p)))
    if not any(os.path.basename(p) == "RGMarchingCubes.so" for p in objects):
        print("FAILED: no RGMarchingCubes.so in %s (found %s)" % (args.plugin_dir, objects))
        return args, None
    return args, objects


def check(condition, what):
    """Records `what` as a failure unless `condition` holds; says so on stderr."""
    if not condition:
        failures.append(what)
        print("FAILED: %s" % what, file=sys.stderr)


def mpi_driver_arguments(default_ranks):
    """The arguments of a driver that runs a ParaView script on several rank counts: --pvbatch,
    --mpiexec, --plugin, --workdir (made here) and --ranks (comma-separated)."""
    parser = argparse.ArgumentParser()
    for name in ("--pvbatch", "--mpiexec", "--plugin", "--workdir"):
        parser.add_argument(name, required=True)
    parser.add_argument("--ranks", default=default_ranks)
    args = parser.parse_args()
    os.makedirs(args.workdir, exist_ok=True)
    return args


def mpi_environment():
    """The environment for mpiexec: Open MPI refuses root without these."""
    return dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def finish(name):
    """The driver's exit code once its checks are done: 1, with the number that failed, when
    any did."""
    if failures:
        print("%s: %d check(s) failed" % (name, len(failures)), file=sys.stderr)
        return 1
    print("%s: all checks passed" % name)
    return 0


def run(command, timeout=900, env=None, tail=None, preexec_fn=None):
    """Runs `command`, prints it and its output (the last `tail` characters of each stream when
    given), and returns the finished process. `preexec_fn` runs in the child before the command
    (limits, signals)."""
    print("+ " + " ".join(command), flush=True)
    result = subprocess.run(command, capture_output=True, text=True, errors="replace",
                            timeout=timeout, env=env, preexec_fn=preexec_fn)
    print(result.stdout[-tail:] if tail else result.stdout)
    print(result.stderr[-tail:] if tail else result.stderr, file=sys.stderr)
    return result


def xvfb_run(xvfb_run_program, command):
    """`command` under a private X server that never resets (see XVFB_SERVER_ARGS)."""
    return [xvfb_run_program, "-a", "-s", XVFB_SERVER_ARGS] + command


def mpiexec_command(mpiexec, ranks):
    """`mpiexec -n ranks` with the flags Open MPI needs to run more ranks than cores: the
    pipeline command's own rule (Scripts/rgmc_common.py)."""
    return rgmc_common.mpiexec_command(ranks, mpiexec)
