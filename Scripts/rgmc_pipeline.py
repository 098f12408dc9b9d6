"""RGMC's pipeline command: extract the surface of one structure from a CT or MRI volume.

Run with ParaView's pvbatch:

  pvbatch Scripts/rgmc_pipeline.py --input head.vti --isovalue 400 --seed 0,0,105 \\
      --output out/skull --screenshot out/skull.png --ranks 2

reads the volume, grows the surface through the vertex nearest to each seed (Region-Growing
Marching Cubes, on --ranks MPI ranks), makes the pieces one watertight mesh and smooths it (Seam
Repair), writes <output>.stl and <output>.vtp (one mesh, seam vertices merged) and
<output>.json (what was done, the mesh checks, timings) and, with --screenshot, a picture.
--decimate FRACTION (and/or --max-error DISTANCE) reduces the mesh before it is written (Decimate
Surface: quadric-error edge collapses, closed and the same on any number of ranks); the report
then has the triangles before and after, the distances to the undecimated surface and the
volume's change.
--input also takes a DICOM series (a directory, or one of its files) and a NIfTI-1 file
(.nii, .nii.gz), read by the plugin's distributed readers (each rank reads its own slices).
Rendering needs an X server (run under xvfb-run when there is no display).
"""

import argparse
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rgmc_common  # noqa: E402

MODES = {"seeded": "Seeded", "largest": "Largest Component", "all": "All Components"}
SMOOTHING = {"laplacian": "Laplacian", "sinc": "Windowed Sinc", "none": "None"}
MEASURES = {"area": "SurfaceArea", "volume": "EnclosedVolume", "border_cap_area": "BorderCapArea",
            "area_before_smoothing": "SurfaceAreaBeforeSmoothing",
            "volume_before_smoothing": "EnclosedVolumeBeforeSmoothing"}
CHECKS = ["UniquePoints", "Triangles", "Edges", "BoundaryEdges", "VolumeBorderEdges",
          "NonManifoldEdges", "EulerCharacteristic", "Closed"]


def parse_seed(text):
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 3:
        raise argparse.ArgumentTypeError("a seed is x,y,z in world coordinates, not %r" % text)
    return values


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog=os.environ.get("RGMC_PROG", "pvbatch rgmc_pipeline.py"),
        description="Extract the surface of the structure nearest to one or more seed points "
        "(seeded, distributed region-growing marching cubes) and write it as STL and VTP.",
        epilog="Examples: CT bone: --isovalue 400 (HU); CT skin: --isovalue -300; MRI: an "
        "intensity between the tissue and the background, e.g. half the tissue's value. "
        "--input phantom:256 makes the project's CT phantom instead of reading a file.")
    parser.add_argument("--input", required=True,
                        help="a DICOM series (a directory, or one of its files), a NIfTI-1 file "
                        "(.nii, .nii.gz), another volume ParaView can read (.vti, .mha, ...), or "
                        "phantom:N")
    parser.add_argument("--isovalue", type=float, required=True,
                        help="the surface's value, in the array's units (HU for CT)")
    parser.add_argument("--seed", type=parse_seed, action="append", default=[],
                        metavar="X,Y,Z", help="a seed point in world coordinates (repeatable)")
    parser.add_argument("--mode", choices=sorted(MODES), default="seeded",
                        help="seeded (default): the seeds' surfaces; largest: the largest "
                        "connected surface; all: every surface")
    parser.add_argument("--radius", type=float, default=10.0,
                        help="how far from each seed its surface is searched (world units, "
                        "default 10)")
    parser.add_argument("--array", help="the point array to contour (default: the first "
                        "one-component point array)")
    parser.add_argument("--smooth", choices=["laplacian", "sinc", "none"], default="laplacian",
                        help="smoothing of the repaired mesh: laplacian (default; relaxation "
                        "0.01), sinc (windowed sinc, no shrinkage) or none")
    parser.add_argument("--iterations", type=int, default=20,
                        help="smoothing iterations (default 20)")
    parser.add_argument("--decimate", type=float, metavar="FRACTION",
                        help="remove this fraction of the triangles (between 0 and 1, e.g. 0.9 "
                        "keeps a tenth) after smoothing, keeping the mesh closed (Decimate "
                        "Surface)")
    parser.add_argument("--no-distance", action="store_true",
                        help="with --decimate or --max-error: do not measure the distance to the "
                        "undecimated surface (Decimate Surface's Compute Distance off)")
    parser.add_argument("--max-error", type=float, metavar="DISTANCE",
                        help="decimate with at most this quadric error per collapse (world "
                        "units); with --decimate, whichever stops first; alone, as many "
                        "triangles go as the error allows (up to 99.9%%)")
    parser.add_argument("--output", required=True,
                        help="output prefix: writes PREFIX.<format> for each of --formats and "
                        "PREFIX.json")
    parser.add_argument("--formats", default="stl,vtp",
                        help="comma-separated formats to write: stl, ply, vtp (default stl,vtp)")
    parser.add_argument("--screenshot", help="also render the surface to this PNG")
    parser.add_argument("--beside-contour", action="store_true",
                        help="with --screenshot: the picture shows ParaView's Contour of the "
                        "whole volume at the same isovalue on the left, the extracted surface "
                        "with its seeds marked on the right")
    parser.add_argument("--color-by", choices=["solid", "rank", "component"], default="solid",
                        help="colour of the picture: solid, by rank (the decomposition), or by "
                        "component")
    parser.add_argument("--ranks", type=int, default=1,
                        help="number of MPI ranks (default 1); the command re-runs itself "
                        "under mpiexec when it is not already running on that many")
    parser.add_argument("--threads", type=int,
                        help="threads per rank (default: this machine's cores over the ranks, "
                        "unless VTK_SMP_BACKEND_IN_USE or VTK_SMP_MAX_THREADS is set; at most "
                        "its cores); the surface is the same on any")
    parser.add_argument("--plugin", help="the plugin library (default: found in $RGMC_BUILD_DIR or build/)")
    parser.add_argument("--connect", metavar="HOST:PORT",
                        help="run on a pvserver (e.g. mpiexec -n 8 pvserver on a cluster) instead "
                        "of here: run this command with pvpython; the server reads --input and "
                        "writes the surface files on its own file system")
    parser.add_argument("--server-plugin", metavar="PATH",
                        help="with --connect: the plugin library's path on the server (default: "
                        "the --plugin path)")
    args = parser.parse_args(argv)
    if args.mode == "seeded" and not args.seed:
        parser.error("the seeded mode needs at least one --seed x,y,z")
    if args.ranks < 1:
        parser.error("--ranks must be at least 1")
    if args.connect and args.ranks != 1:
        parser.error("--ranks is for pvbatch here; with --connect the server's ranks are used")
    if args.threads is not None and args.threads < 1:
        parser.error("--threads must be at least 1")
    if args.connect and args.threads is not None:
        parser.error("--threads is for pvbatch here; a pvserver's threads are set where it "
                     "starts (VTK_SMP_BACKEND_IN_USE, VTK_SMP_MAX_THREADS)")
    if args.beside_contour and not args.screenshot:
        parser.error("--beside-contour needs --screenshot")
    if args.iterations < 0:
        parser.error("--iterations must be at least 0")
    if args.decimate is not None and not 0 < args.decimate < 1:
        parser.error("--decimate takes the fraction of the triangles to remove, greater than 0 "
                     "and less than 1, not %g" % args.decimate)
    if args.max_error is not None and not args.max_error > 0:
        parser.error("--max-error takes a positive distance, not %g" % args.max_error)
    args.formats = [f.strip().lower() for f in args.formats.split(",") if f.strip()]
    for f in args.formats:
        if f not in ("stl", "ply", "vtp"):
            parser.error("--formats takes stl, ply and vtp, not %r" % f)
    return args


class WriteFailed(Exception):
    """A file could not be written; the earlier file at its path, if any, is left as it was."""


def replace_file(path, write):
    """Writes a file beside `path` with write(temporary path) (True when it succeeded), flushed to
    the disk, then renames it over `path`: an earlier file there is replaced only by a complete
    one, and on any failure it is left as it was and nothing is left beside it. The temporary
    keeps the extension, for writers that choose their format by it."""
    target = os.path.realpath(path)  # through a symbolic link, to the file it names
    stem, extension = os.path.splitext(target)
    temporary = "%s.rgmc-%d.part%s" % (stem, os.getpid(), extension)
    try:
        ok = write(temporary)
        if ok and os.path.exists(temporary):
            with open(temporary, "rb+") as written:
                os.fsync(written.fileno())
            os.replace(temporary, target)
            return True
        problem = "the writer failed (its error is above)"
    except OSError as error:
        problem = error.strerror or str(error)
    try:
        os.unlink(temporary)
    except OSError:
        pass
    print("rgmc_pipeline: error: cannot write %s: %s; %s" % (
        path, problem, "the earlier file is left as it was" if os.path.exists(target)
        else "nothing was written"), file=sys.stderr)
    return False


def write_text(path, text):
    with open(path, "w") as out:
        out.write(text)
    return True


def write_surface(path, proxy):
    """Writes the surface with the Merged Surface Writer (which replaces the file only when the
    new one is complete, on every rank), and says whether it succeeded."""
    from paraview import simple
    writer = simple.CreateWriter(path, proxy=proxy, FileType="Binary")
    writer.UpdatePipeline()
    writer.UpdatePropertyInformation()
    failed = writer.GetProperty("ErrorCode")
    ok = failed is None or not failed.GetData()
    simple.Delete(writer)
    if not ok:
        print("rgmc_pipeline: error: cannot write %s (the writer's error is above); %s" % (
            path, "the earlier file is left as it was" if os.path.exists(path)
            else "nothing was written"), file=sys.stderr)
    return ok


def measures(fields, medical):
    """Seam Repair's area and enclosed volume (JSON-ready: null for no volume), in the data's
    units: mm for DICOM, NIfTI and the phantom, with the volume in ml too."""
    import math
    values = {}
    for key, name in MEASURES.items():
        value = fields.GetArrayInformation(name).GetComponentRange(0)[0]
        values[key] = None if math.isnan(value) else value
    values["units"] = "mm" if medical else "the data's units"
    if medical:
        for key in ("volume", "volume_before_smoothing"):
            if values[key] is not None:
                values[key + "_ml"] = values[key] / 1000.0
    return values


def describe_measures(m):
    """One line: area and volume after smoothing, before smoothing, and the border's part."""
    area, volume = ("mm^2", "mm^3") if m["units"] == "mm" else ("units^2", "units^3")

    def vol(key):
        if m[key] is None:
            return "no enclosed volume (the surface has a hole inside the volume)"
        ml = " (%.2f ml)" % (m[key] / 1000.0) if m["units"] == "mm" else ""
        return "volume %.6g %s%s" % (m[key], volume, ml)

    text = "area %.6g %s, %s" % (m["area"], area, vol("volume"))
    if m["area_before_smoothing"] != m["area"] or m["volume_before_smoothing"] != m["volume"]:
        text += "; before smoothing area %.6g %s, %s" % (
            m["area_before_smoothing"], area, vol("volume_before_smoothing"))
        if m["volume"] and m["volume_before_smoothing"]:
            text += " (smoothing changed it by %+.2f%%)" % (
                100.0 * (m["volume"] / m["volume_before_smoothing"] - 1.0))
    if m["border_cap_area"]:
        text += "; closed across the volume's border by %.6g %s" % (m["border_cap_area"], area)
    return text


def decimate(repaired, args, report):
    """Decimate Surface after the repair; its triangles, distances and volume change go into
    the report and the summary."""
    from paraview import simple
    reduction = args.decimate if args.decimate is not None else 0.999
    decimated = simple.RGDecimate(Input=repaired, TargetReduction=reduction,
                                  MaximumError=args.max_error or 0.0,
                                  ComputeDistance=0 if args.no_distance else 1)
    started = time.time()
    decimated.UpdatePipeline()
    seconds = time.time() - started
    information = decimated.GetDataInformation()
    fields = information.DataInformation.GetFieldDataInformation()
    before = report["checks"]["Triangles"]
    checks = {name: int(fields.GetArrayInformation(name).GetComponentRange(0)[0]) for name in CHECKS}
    volume_before = report["measures"]["volume"]
    volume = fields.GetArrayInformation("EnclosedVolume").GetComponentRange(0)[0]
    entry = {
        "target_reduction": args.decimate, "max_error": args.max_error, "seconds": round(seconds, 4),
        "triangles_before": before, "triangles": checks["Triangles"], "checks": checks,
        "quadric_error": fields.GetArrayInformation("DecimationQuadricError").GetComponentRange(0)[0],
        "area": fields.GetArrayInformation("SurfaceArea").GetComponentRange(0)[0],
        "volume": None if volume != volume else volume,
    }
    entry["volume_change_percent"] = (
        100.0 * (volume / volume_before - 1.0) if volume_before and volume == volume else None)
    # Measured by the filter where the triangles are (nothing is gathered here).
    for key, name in (("hausdorff", "DecimationHausdorffDistance"),
                      ("mean", "DecimationMeanDistance")):
        entry[key] = None if args.no_distance else \
            fields.GetArrayInformation(name).GetComponentRange(0)[0]
    report["decimation"] = entry
    print("decimated:  %d -> %d triangles (%.1f%% removed) in %.3f s; %s, Euler characteristic %d" % (
        before, checks["Triangles"], 100.0 * (1 - checks["Triangles"] / before), seconds,
        "closed" if checks["Closed"] else "not closed", checks["EulerCharacteristic"]))
    change = entry["volume_change_percent"]
    print("distance:   %s%s" % (
        "not measured (--no-distance)" if args.no_distance else
        "Hausdorff %.4g, mean %.4g to the undecimated surface" % (entry["hausdorff"], entry["mean"]),
        "; volume changed by %+.3f%%" % change if change is not None else ""))
    return decimated


def new_view(size):
    from paraview import simple
    view = simple.CreateRenderView()
    view.ViewSize = size
    view.OrientationAxesVisibility = 1
    view.Background = [0.11, 0.12, 0.15]
    try:
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    return view


def show_surface(source, view, color_by="solid"):
    from paraview import simple
    display = simple.Show(source, view)
    if color_by == "solid":
        if display.ColorArrayName[1]:
            simple.ColorBy(display, None)
        display.DiffuseColor = [0.93, 0.89, 0.80]
        display.AmbientColor = [0.93, 0.89, 0.80]
    else:
        name = "RankId" if color_by == "rank" else "ComponentId"
        simple.ColorBy(display, ("CELLS", name))
        display.RescaleTransferFunctionToDataRange(True, False)
    return display


def aim(view, bounds):
    """From the front (+y, a CT's face), to the right and above, z up."""
    import math
    centre = [(bounds[2 * a] + bounds[2 * a + 1]) / 2 for a in range(3)]
    radius = 0.5 * math.sqrt(sum((bounds[2 * a + 1] - bounds[2 * a]) ** 2 for a in range(3)))
    # Far enough for the bounding sphere to fill the view angle, as ResetCamera places it.
    direction = [1.2, 2.0, 0.9]
    norm = math.sqrt(sum(d * d for d in direction))
    distance = radius / math.sin(math.radians(view.CameraViewAngle / 2))
    view.CameraFocalPoint = centre
    view.CameraPosition = [c + distance * d / norm for c, d in zip(centre, direction)]
    view.CameraViewUp = [0, 0, 1]


def render(source, args, ranks):
    from paraview import simple
    view = new_view([1200, 900])
    display = show_surface(source, view, args.color_by)
    aim(view, source.GetDataInformation().GetBounds())
    os.makedirs(os.path.dirname(os.path.abspath(args.screenshot)), exist_ok=True)
    if not replace_file(args.screenshot, lambda path: simple.SaveScreenshot(
            path, view, ImageResolution=[1200, 900]) is not False):
        raise WriteFailed(args.screenshot)
    simple.Delete(display)
    simple.Delete(view)


def render_beside_contour(volume, array, source, args):
    """Contour of the whole volume (left) beside the extracted surface with its seeds (right),
    seen by the same camera."""
    from paraview import simple
    contour = simple.Contour(Input=volume, ContourBy=["POINTS", array],
                             Isosurfaces=[args.isovalue], ComputeScalars=0)
    contour.UpdatePipeline()
    bounds = contour.GetDataInformation().GetBounds()
    size = max(bounds[2 * a + 1] - bounds[2 * a] for a in range(3))
    left, right = new_view([1000, 900]), new_view([1000, 900])
    shown = [(show_surface(contour, left), left), (show_surface(source, right), right)]
    for seed in args.seed:
        ball = simple.Sphere(Center=seed, Radius=0.025 * size, ThetaResolution=32,
                             PhiResolution=32)
        display = simple.Show(ball, right)
        display.DiffuseColor = display.AmbientColor = [0.85, 0.15, 0.1]
        shown.append((display, right))
    titles = ["Contour at %g: every surface at that value" % args.isovalue,
              "RGMC, %d seed%s: the structure through %s" % (
                  len(args.seed), "" if len(args.seed) == 1 else "s",
                  "it" if len(args.seed) == 1 else "them")]
    for view, title in zip((left, right), titles):
        text = simple.Text(Text=title)
        display = simple.Show(text, view)
        display.FontSize = 20
        display.WindowLocation = "Upper Center"
        shown.append((display, view))
    aim(left, bounds)
    aim(right, bounds)
    layout = simple.CreateLayout("RGMC beside Contour")
    layout.SplitHorizontal(0, 0.5)
    simple.AssignViewToLayout(view=left, layout=layout, hint=1)
    simple.AssignViewToLayout(view=right, layout=layout, hint=2)
    os.makedirs(os.path.dirname(os.path.abspath(args.screenshot)), exist_ok=True)
    if not replace_file(args.screenshot, lambda path: simple.SaveScreenshot(
            path, layout, ImageResolution=[2000, 900]) is not False):
        raise WriteFailed(args.screenshot)
    for display, view in shown:
        simple.Hide(display.Input, view)
    return contour.GetDataInformation().GetNumberOfCells()


def picture(volume, array, final, args, ranks, report):
    """The screenshot, if asked for (WriteFailed when it cannot be written)."""
    if args.screenshot and args.beside_contour:
        report["contour_triangles"] = render_beside_contour(volume, array, final, args)
        report["outputs"].append(args.screenshot)
        print("contour:    ParaView's Contour at %g gives %d triangles: every surface at that "
              "value (left in the picture), %d of them the structure's" % (
                  args.isovalue, report["contour_triangles"], report["triangles"]))
    elif args.screenshot:
        render(final, args, ranks)
        report["outputs"].append(args.screenshot)


class Stages:
    """The job's wall time in consecutive stages (each from the end of the one before), so that
    they add up to the whole; the first, start-up, is the process's age when the script began
    (pvbatch's own start and MPI's), or, when the command started mpiexec itself, the time since
    the first process started (RGMC_JOB_STARTED, which it passes on)."""

    def __init__(self):
        self.last = time.time()
        started = process_age()
        try:
            started = max(started, self.last - float(os.environ.get("RGMC_JOB_STARTED", "")))
        except ValueError:
            pass
        self.seconds = {"start-up": started}

    def mark(self, name):
        now = time.time()
        self.seconds[name] = self.seconds.get(name, 0.0) + now - self.last
        self.last = now

    def report(self):
        return {name: round(value, 4) for name, value in self.seconds.items()}

    def total(self):
        return sum(self.seconds.values())


def process_age():
    """Seconds since this process started (Linux /proc), or 0 where that is not known."""
    try:
        with open("/proc/self/stat") as stat:
            started = int(stat.read().rsplit(")", 1)[1].split()[19])
        with open("/proc/uptime") as uptime:
            return max(0.0, float(uptime.read().split()[0]) - started / os.sysconf("SC_CLK_TCK"))
    except (OSError, ValueError, IndexError):
        return 0.0


def main(argv):
    stages = Stages()
    args = parse_args(argv)
    if args.connect:
        rgmc_common.connect(args.connect)
    ranks = rgmc_common.number_of_ranks()
    threads = None
    if not args.connect:
        if args.ranks > 1 and ranks == 1:
            return rgmc_common.relaunch(
                os.path.abspath(__file__), argv, args.ranks, render=bool(args.screenshot),
                threads=args.threads or rgmc_common.cores_per_rank(args.ranks),
                env={"RGMC_JOB_STARTED": repr(time.time() - process_age())})
        if ranks != args.ranks:
            print("note: running on %d MPI ranks (--ranks %d)" % (ranks, args.ranks))
        threads = rgmc_common.use_threads(args.threads, ranks)

    from paraview import simple
    from vtkmodules.vtkCommonCore import vtkLogger
    # The command prints the seam repair's checks itself; its log line would say them twice.
    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_WARNING)
    rgmc_common.load_plugin(args.plugin, args.server_plugin)

    stages.mark("start-up")
    started = time.time()
    volume = rgmc_common.open_volume(args.input)
    volume.UpdatePipeline()
    read_seconds = time.time() - started
    kind, dims, arrays = rgmc_common.image_summary(volume)
    if kind != "vtkImageData":
        raise rgmc_common.UsageError("%s holds %s, not a volume (vtkImageData)" % (args.input, kind))
    scalars = [a for a in arrays if a[1] == 1]
    if args.array:
        if args.array not in [a[0] for a in arrays]:
            raise rgmc_common.UsageError("%s has no point array %r (it has: %s)" % (
                args.input, args.array, ", ".join(a[0] for a in arrays) or "none"))
        array = args.array
    elif scalars:
        array = scalars[0][0]
    else:
        raise rgmc_common.UsageError("%s has no one-component point array to contour" % args.input)
    value_range = [a[2] for a in arrays if a[0] == array][0]

    surface = simple.RGMarchingCubes(
        Input=volume, ContourBy=["POINTS", array], Isovalue=args.isovalue,
        SeedPoints=[c for seed in args.seed for c in seed], SeedSearchRadius=args.radius,
        ExtractionMode=MODES[args.mode])
    started = time.time()
    # On several ranks a reader other than the plugin's reads its piece again here, with the
    # ghost layer the filter asks for (the plugin's readers and the phantom made it already).
    surface.UpdatePipeline()
    total_seconds = time.time() - started + read_seconds
    # The extraction alone, as the filter timed it (the first rank's wall time).
    surface.UpdatePropertyInformation()
    extract_seconds = surface.GetPropertyValue("ExtractionSeconds")
    triangles = surface.GetDataInformation().GetNumberOfCells()
    stages.mark("read and extract")

    report = {
        "input": args.input, "dimensions": dims, "array": array, "array_range": list(value_range),
        "isovalue": args.isovalue, "mode": args.mode, "seeds": args.seed,
        "seed_search_radius": args.radius, "ranks": ranks, "threads": threads,
        "triangles": triangles,
        "read_seconds": round(read_seconds, 4),
        "extract_seconds": round(extract_seconds, 4), "total_seconds": round(total_seconds, 4),
        "outputs": [],
    }
    print("input:      %s (%d x %d x %d, array %s, range %g to %g)" % (
        args.input, dims[0], dims[1], dims[2], array, value_range[0], value_range[1]))
    summary = rgmc_common.reader_summary(volume)
    if summary:
        print("read:       %s" % summary)
        report["reader"] = summary
    print("isovalue:   %g   mode: %s   ranks: %d%s" % (
        args.isovalue, args.mode, ranks,
        " (pvserver at %s)" % args.connect if args.connect else "   threads: %d a rank" % threads))
    for seed in args.seed:
        print("seed:       (%g, %g, %g)" % tuple(seed))
    print("surface:    %d triangles" % triangles)
    print("seconds:    %.3f extraction (%.3f with reading the volume)" % (
        extract_seconds, total_seconds))
    if triangles == 0:
        print("no surface extracted: nothing written (see the warning above)", file=sys.stderr)
        return 2

    # One watertight mesh from the ranks' pieces, smoothed identically on any number of ranks.
    repaired = simple.RGSeamRepair(Input=surface, SmoothingMethod=SMOOTHING[args.smooth],
                                   NumberOfIterations=args.iterations)
    started = time.time()
    repaired.UpdatePipeline()
    report["repair_seconds"] = round(time.time() - started, 4)
    stages.mark("repair")
    report["smoothing"] = {"method": args.smooth, "iterations": args.iterations}
    data_information = repaired.GetDataInformation()  # keep it alive while reading it
    fields = data_information.DataInformation.GetFieldDataInformation()
    report["checks"] = {name: int(fields.GetArrayInformation(name).GetComponentRange(0)[0])
                        for name in CHECKS}
    checks = report["checks"]
    print("mesh:       %d unique points, %d triangles, %d edges; %d boundary edges (%d more on the "
          "volume's border), %d non-manifold; Euler characteristic %d: %s" % (
              checks["UniquePoints"], checks["Triangles"], checks["Edges"], checks["BoundaryEdges"],
              checks["VolumeBorderEdges"], checks["NonManifoldEdges"], checks["EulerCharacteristic"],
              "closed" if checks["Closed"] else "not closed"))
    print("smoothing:  %s, %d iterations (%.3f s with the seam repair)" % (
        args.smooth, args.iterations, report["repair_seconds"]))
    report["measures"] = measures(fields, medical=bool(summary) or args.input.startswith("phantom:"))
    print("measures:   %s" % describe_measures(report["measures"]))

    stages.mark("measures")
    final = repaired
    if args.decimate is not None or args.max_error is not None:
        final = decimate(repaired, args, report)
        stages.mark("decimate and distance")

    directory = os.path.dirname(os.path.abspath(args.output))
    os.makedirs(directory, exist_ok=True)
    for extension in args.formats:
        # The plugin's Merged Surface Writer: one mesh, seam vertices merged, from any rank count.
        path = args.output + "." + extension
        if not write_surface(path, final):
            return 1
        report["outputs"].append(path)
    stages.mark("write")
    try:
        picture(volume, array, final, args, ranks, report)
    except WriteFailed:
        return 1
    if args.screenshot:
        stages.mark("picture")
    report["stages_seconds"] = stages.report()
    report["wall_seconds"] = round(stages.total(), 4)
    print("stages:     %s; %.2f s in all" % (", ".join(
        "%s %.2f s" % item for item in stages.seconds.items()), stages.total()))
    if not replace_file(args.output + ".json",
                        lambda path: write_text(path, json.dumps(report, indent=2) + "\n")):
        return 1
    print("written:    %s" % ", ".join(report["outputs"] + [args.output + ".json"]))
    return 0


if __name__ == "__main__":
    rgmc_common.run(main, "rgmc_pipeline")
