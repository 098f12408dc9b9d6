"""Shared by RGMC's pvbatch commands: finding and loading the plugin, opening a volume, and
running under MPI (re-launching the command under mpiexec when --ranks asks for more ranks)."""

import glob
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


class UsageError(Exception):
    """A problem with the command line or the input, reported without a traceback."""


def build_dir():
    """The project's build tree, as ./rgmc chooses it: $RGMC_BUILD_DIR, else <root>/build."""
    return os.path.abspath(os.environ.get("RGMC_BUILD_DIR") or os.path.join(ROOT, "build"))


def find_plugin(explicit=None):
    """The plugin library: --plugin, $RGMC_PLUGIN, or the project's build tree (build_dir())."""
    candidates = [explicit, os.environ.get("RGMC_PLUGIN")]
    candidates += sorted(glob.glob(os.path.join(
        build_dir(), "lib", "paraview-*", "plugins", "RGMarchingCubes", "RGMarchingCubes.so")))
    for path in candidates:
        if path and os.path.isfile(path):
            return os.path.abspath(path)
    if explicit:
        raise UsageError("no plugin library at %s" % explicit)
    return None


def connect(address):
    """Connects this pvpython to a running pvserver (HOST:PORT or cs://HOST:PORT): the pipeline
    then runs on the server's ranks, on ParaView's decomposition there."""
    from paraview import servermanager, simple
    text = address[len("cs://"):] if address.startswith("cs://") else address
    host, _, port = text.rpartition(":")
    try:
        port = int(port)
    except ValueError:
        host = ""
    if not host:
        raise UsageError("--connect expects HOST:PORT (a pvserver's address), not %r" % address)
    try:
        connection = simple.Connect(host, port)
    except Exception as error:  # ParaView raises RuntimeError; be as clear for any other
        connection, message = None, str(error)
    else:
        message = "no server answered"
    if connection is None or servermanager.ActiveConnection is None:
        raise UsageError("cannot connect to a pvserver at %s:%d (%s): start one with "
                         "`mpiexec -n N pvserver --server-port=%d` there" % (host, port, message, port))


def is_client():
    """Whether this ParaView is a client connected to a separate pvserver."""
    from paraview import servermanager
    return servermanager.ActiveConnection is not None and servermanager.ActiveConnection.IsRemote()


def load_plugin(explicit=None, server_path=None):
    """Loads the plugin into ParaView and adds its proxies (RGMarchingCubes, CTPhantom, ...) to
    paraview.simple. A plugin already loaded (auto-loaded from PV_PLUGIN_PATH) is used as is.
    Connected to a pvserver, the plugin is loaded on the client and on the server (from
    `server_path`, a path on the server's machine, by default the client's path)."""
    from paraview import simple
    if not is_client():
        if hasattr(simple, "RGMarchingCubes") and not explicit:
            return None
        path = find_plugin(explicit)
        if path is None:
            raise UsageError("cannot find the RGMarchingCubes plugin: build it (./rgmc build), "
                             "or pass --plugin PATH, or set RGMC_PLUGIN")
        simple.LoadPlugin(path, ns=vars(simple))
        return path
    path = find_plugin(explicit)
    if path:
        simple.LoadPlugin(path, remote=False, ns=vars(simple))
    server_path = server_path or path
    if not server_path:
        raise UsageError("give the plugin's path on the server with --server-plugin PATH")
    try:
        simple.LoadPlugin(server_path, remote=True, ns=vars(simple))
    except RuntimeError:
        raise UsageError(
            "the server cannot load the RGMC plugin from %s (its message is above): build and "
            "install the plugin on the server's machine against the server's ParaView (README: "
            "Running on a cluster) and give its path there with --server-plugin" % server_path)
    return server_path


def number_of_ranks():
    """How many MPI ranks the pipeline runs on: this pvbatch's, or the connected pvserver's."""
    from paraview import servermanager
    if is_client():
        return servermanager.ActiveConnection.GetNumberOfDataPartitions()
    return servermanager.vtkProcessModule.GetProcessModule().GetNumberOfLocalPartitions()


def mpiexec_command(ranks, mpiexec=None, unbound=False):
    """mpiexec (the one on PATH unless given) with the flags this MPI needs to run `ranks`
    processes on this machine; `unbound`: each free to use every core (for threads within a
    rank; Open MPI binds each rank to one core by default, MPICH does not bind)."""
    mpiexec = mpiexec or shutil.which("mpiexec")
    if not mpiexec:
        raise UsageError("--ranks %d needs mpiexec (Debian: apt-get install openmpi-bin)" % ranks)
    command = [mpiexec, "-n", str(ranks)]
    try:
        version = subprocess.run([mpiexec, "--version"], capture_output=True, text=True).stdout
    except OSError:
        version = ""
    if "Open MPI" in version or "OpenRTE" in version:
        # More ranks than cores is fine for testing. Open MPI 5 removed --oversubscribe; this
        # spelling works on 4 and 5.
        command += ["--map-by", ":OVERSUBSCRIBE"]
        if unbound:
            command += ["--bind-to", "none"]
    return command


def cores_per_rank(ranks):
    """The cores this process may run on, shared among the ranks on this node: under an mpiexec
    that binds each rank to a core, 1; run alone, or relaunched unbound, the node's cores over
    its ranks."""
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    local = os.environ.get("OMPI_COMM_WORLD_LOCAL_SIZE") or os.environ.get("MPI_LOCALNRANKS")
    try:
        ranks = int(local) if local else ranks
    except ValueError:
        pass
    return max(1, cores // max(1, ranks))


def use_threads(requested, ranks):
    """Runs VTK's (and the plugin's) threaded filters on `requested` threads per rank; None:
    the cores this rank has (cores_per_rank), unless VTK_SMP_BACKEND_IN_USE or
    VTK_SMP_MAX_THREADS is set, which VTK then follows as it is. Debian's VTK defaults to its
    Sequential backend (one thread): STDThread is taken instead when more are asked for.
    Returns the threads the filters will use. The surface is the same to the bit on any."""
    from vtkmodules.vtkCommonCore import vtkSMPTools
    if requested is None:
        if "VTK_SMP_BACKEND_IN_USE" in os.environ or "VTK_SMP_MAX_THREADS" in os.environ:
            return vtkSMPTools.GetEstimatedNumberOfThreads()
        requested = cores_per_rank(ranks)
    if requested > 1 and vtkSMPTools.GetBackend() == "Sequential":
        if not hasattr(vtkSMPTools, "SetBackend") or not vtkSMPTools.SetBackend("STDThread"):
            print("note: this VTK has no threaded backend: running on 1 thread", file=sys.stderr)
            return 1
    vtkSMPTools.Initialize(requested)
    given = vtkSMPTools.GetEstimatedNumberOfThreads()
    if given < requested:
        print("note: VTK runs at most %d threads a process here (its cores), not %d" % (
            given, requested), file=sys.stderr)
    return given


def mpi_environment():
    # A pvbatch started without mpiexec is an MPI singleton; its launcher variables would
    # confuse the mpiexec started from it.
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_", "PMI_"))}
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        # Open MPI refuses to run as root unless told; harmless for other MPIs.
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    return env


def relaunch(script, argv, ranks, render, threads=1, env=None):
    """Runs `script argv` again with pvbatch on `ranks` MPI ranks, with `env` added to the
    environment; returns its exit code. With more than one thread a rank, the ranks are not
    bound to one core each (Open MPI binds them to cores by default)."""
    pvbatch = shutil.which("pvbatch")
    if not pvbatch:
        raise UsageError("cannot find pvbatch on PATH")
    command = mpiexec_command(ranks, unbound=threads > 1) + [pvbatch, "--mpi"]
    if render:
        # Under MPI, pvbatch renders off screen (it hangs otherwise); it still needs an X server.
        command.append("--force-offscreen-rendering")
    command += [script] + list(argv)
    sys.stdout.flush()
    environment = mpi_environment()
    environment.update(env or {})
    return subprocess.call(command, env=environment)


def is_dicom_file(path):
    """Whether `path` starts as a DICOM Part 10 file does (128 bytes, then "DICM")."""
    try:
        with open(path, "rb") as f:
            return f.read(132)[128:] == b"DICM"
    except OSError:
        return False


def open_volume(spec):
    """A ParaView source for `spec`: a DICOM series (a directory, or one file of the series:
    the plugin's DICOM Series reader), a NIfTI-1 file (.nii, .nii.gz: the plugin's NIfTI Volume
    reader), another file ParaView can read, or phantom:N (the CT phantom at N^3) or
    phantom:NX,NY,NZ. The plugin's readers read a piece per rank."""
    from paraview import simple
    if spec.startswith("phantom:"):
        try:
            dims = [int(v) for v in spec[len("phantom:"):].split(",")]
        except ValueError:
            dims = []
        if len(dims) == 1:
            dims *= 3
        if len(dims) != 3 or min(dims) < 2:
            raise UsageError("phantom:N or phantom:NX,NY,NZ expects sizes of at least 2, not %r"
                             % spec)
        return simple.CTPhantom(Dimensions=dims)
    if not is_client() and not os.path.exists(spec):  # a server reads its own file system
        raise UsageError("no such file or directory: %s" % spec)
    path = os.path.abspath(spec)
    if os.path.isdir(path) or path.lower().endswith((".dcm", ".dicom")) or is_dicom_file(path):
        return simple.DICOMSeries(FileName=path)
    if path.lower().endswith((".nii", ".nii.gz")):
        return simple.NIfTIVolume(FileName=path)
    source = simple.OpenDataFile(spec)
    if source is None:
        raise UsageError("ParaView has no reader for %s" % spec)
    return source


def reader_summary(source):
    """What the plugin's readers say they read (size, geometry, scaling), or None."""
    try:
        source.UpdatePropertyInformation()
        return source.GetPropertyValue("Summary") or None
    except (AttributeError, TypeError):
        return None


def image_summary(source):
    """Dimensions and point arrays (name, components, range) of a source's output."""
    info = source.GetDataInformation()
    ext = info.GetExtent()
    dims = [ext[1] - ext[0] + 1, ext[3] - ext[2] + 1, ext[5] - ext[4] + 1]
    arrays = []
    for name in source.PointData.keys():
        array = source.PointData[name]
        arrays.append((name, array.GetNumberOfComponents(), array.GetRange(0)))
    return info.GetDataSetTypeAsString(), dims, arrays


def run(main, name):
    """Runs main(argv) as a pvbatch command. Success returns normally: under MPI, pvbatch must
    reach its own finalization (sys.exit(0) would skip it and make mpiexec report an abnormal
    end). A failure exits at once with its code, which ends an MPI job instead of leaving the
    other ranks waiting."""
    try:
        code = main(sys.argv[1:])
    except UsageError as error:
        print("%s: error: %s" % (name, error), file=sys.stderr)
        code = 2
    if code:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
