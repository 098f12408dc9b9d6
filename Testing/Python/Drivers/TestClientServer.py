"""The plugin in client-server mode, as on a cluster: `mpiexec -n N pvserver` on loopback and a
pvpython client that connects, loads the plugin on client and server, runs the pipeline
(PluginSummary.py: extraction in every mode, seam repair with both smoothings, the merged PLY)
and fetches the results, which must equal pvbatch's 1-rank results exactly. Then the bad cases:
a client whose server cannot load the plugin (the pipeline command's message), and the filter
on a non-image input (VTK's message naming the required type). Every server is shut down, even
when a check fails.

  python3 TestClientServer.py --pvbatch pvbatch --pvpython pvpython --pvserver pvserver \
      --mpiexec mpiexec --plugin RGMarchingCubes.so --pipeline rgmc_pipeline.py --workdir DIR
"""

import argparse
import contextlib
import json
import os
import signal
import socket
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Modules"))
import SummaryCompare  # noqa: E402
import rgmc_testing  # noqa: E402


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def pvserver(args, ranks, log_path):
    """A pvserver on `ranks` MPI ranks on a free loopback port; yields the port. The whole
    process group is killed on the way out if it has not exited by itself."""
    port = free_port()
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    env.pop("PV_PLUGIN_PATH", None)  # the server has only what the client asks it to load
    log = open(log_path, "w")
    server = subprocess.Popen(rgmc_testing.mpiexec_command(args.mpiexec, ranks) +
                              [args.pvserver, "--server-port=%d" % port], stdout=log,
                              stderr=subprocess.STDOUT, env=env, start_new_session=True)
    try:
        deadline = time.time() + 120
        while "Accepting connection" not in open(log_path).read():
            if server.poll() is not None or time.time() > deadline:
                raise RuntimeError("the pvserver did not start:\n" + open(log_path).read()[-2000:])
            time.sleep(0.2)
        yield port
        try:
            server.wait(timeout=60)  # it exits when its client disconnects
        except subprocess.TimeoutExpired:
            pass
    finally:
        if server.poll() is None:
            os.killpg(server.pid, signal.SIGKILL)
            server.wait()
        log.close()


def run(command):
    return rgmc_testing.run(command, tail=3000)


def main():
    parser = argparse.ArgumentParser()
    for name in ("--pvbatch", "--pvpython", "--pvserver", "--mpiexec", "--plugin", "--pipeline", "--workdir"):
        parser.add_argument(name, required=True)
    parser.add_argument("--ranks", default="2,3")
    args = parser.parse_args()
    os.makedirs(args.workdir, exist_ok=True)
    summary_script = rgmc_testing.in_paraview("PluginSummary.py")
    failures = []

    reference_path = os.path.join(args.workdir, "pvbatch-1.json")
    result = run([args.pvbatch, summary_script, "--plugin", args.plugin, "--output", reference_path])
    if result.returncode != 0:
        print("FAILED: the pvbatch reference run failed", file=sys.stderr)
        return 1
    reference = json.load(open(reference_path))

    for ranks in [int(r) for r in args.ranks.split(",")]:
        output = os.path.join(args.workdir, "client-server-%d.json" % ranks)
        with pvserver(args, ranks, os.path.join(args.workdir, "pvserver-%d.log" % ranks)) as port:
            result = run([args.pvpython, summary_script, "--connect", "127.0.0.1:%d" % port,
                          "--plugin", args.plugin, "--output", output])
        if result.returncode != 0 or not os.path.exists(output):
            failures.append("the client of a %d-rank pvserver failed (status %d)" % (ranks, result.returncode))
            continue
        failures += SummaryCompare.compare(json.load(open(output)), reference, ranks,
                                           "client of a %d-rank pvserver" % ranks)

    # A server that cannot load the plugin: the pipeline command says so, writes nothing.
    bad = os.path.join(args.workdir, "no-plugin", "skull")
    with pvserver(args, 2, os.path.join(args.workdir, "pvserver-no-plugin.log")) as port:
        result = run([args.pvpython, args.pipeline, "--connect", "127.0.0.1:%d" % port, "--plugin", args.plugin,
                      "--server-plugin", "/nonexistent/RGMarchingCubes.so", "--input", "phantom:32",
                      "--isovalue", "400", "--seed", "0,0,105", "--output", bad])
    if result.returncode != 2 or "the server cannot load the RGMC plugin from /nonexistent" not in result.stderr:
        failures.append("a server without the plugin: status %d, message %r" % (result.returncode, result.stderr[-500:]))
    if os.path.exists(os.path.dirname(bad)):
        failures.append("a server without the plugin: files were written")

    # A non-image input: VTK's message, on the client, naming the type the filter needs.
    with pvserver(args, 2, os.path.join(args.workdir, "pvserver-non-image.log")) as port:
        result = run([args.pvpython, rgmc_testing.in_paraview("NonImageClient.py"), "127.0.0.1", str(port), args.plugin])
    text = result.stdout + result.stderr
    if "is of type vtkPolyData, but a vtkImageData is required" not in text or \
            "triangles from a sphere's polydata: 0" not in text:
        failures.append("a non-image input did not give VTK's type message and an empty output")

    for failure in failures:
        print("FAILED: " + failure, file=sys.stderr)
    if failures:
        return 1
    print("TestClientServer: clients of %s-rank pvservers get the 1-rank pvbatch results exactly; "
          "bad cases give clear messages" % args.ranks)
    return 0


sys.exit(main())
