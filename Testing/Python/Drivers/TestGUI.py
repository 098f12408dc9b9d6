"""The plugin in the real ParaView GUI, as a user drives it, under a private Xvfb.

ParaView plays TestGUI.xml (its own --test-script mechanism): the plugin auto-loads from
PV_PLUGIN_PATH, the CT phantom comes from the Sources menu, Region-Growing Marching Cubes from the
Filters menu; a seed is typed into the handle's position and added with Add Seed; Apply. While the
playback waits, this driver presses P (a real X key event, through xdotool) over the middle of the
render view, which moves the handle onto the surface under the mouse; the playback adds that seed
and applies again. GUIChecks.py then records, inside the GUI, what ParaView holds and shows.

Checks: the playback succeeded; the filter's SeedPoints hold the typed seed and the picked one;
the picked seed lies on the extracted surface; the surface equals the oracle's (VTK's marching
cubes + connectivity) in triangles; it is visible in the render view as a surface and covers a
real part of it. The picture of the whole window is kept as build/.../TestGUI/paraview-window.png.

  python3 TestGUI.py --paraview paraview --plugin-dir DIR --workdir DIR
"""

import argparse
import json
import os
import shutil
import signal
import struct
import subprocess
import sys
import time
import zlib

import numpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "Modules"))
import rgmc_testing  # noqa: E402

BACKGROUND = (82, 87, 110)  # the render view's background (GUIReady.py sets it), as 8-bit RGB


def read_xwd(path):
    """An X window dump (xwd, ZPixmap, 24 or 32 bits per pixel) as an RGB array."""
    data = open(path, "rb").read()
    header = struct.unpack(">25I", data[:100])
    header_size, _, pixmap_format, _, width, height = header[:6]
    byte_order, bits_per_pixel, bytes_per_line = header[7], header[11], header[12]
    masks, colours = header[14:17], header[19]
    if pixmap_format != 2 or bits_per_pixel not in (24, 32):
        raise ValueError("unexpected xwd format %d with %d bits per pixel" % (pixmap_format, bits_per_pixel))
    step = bits_per_pixel // 8
    offset = header_size + 12 * colours
    rows = numpy.frombuffer(data, numpy.uint8, height * bytes_per_line, offset).reshape(height, bytes_per_line)
    pixels = rows[:, :width * step].reshape(height, width, step).astype(numpy.uint32)
    if byte_order == 1:
        pixels = pixels[:, :, ::-1]
    value = sum(pixels[:, :, i] << (8 * i) for i in range(step))
    channels = []
    for mask in masks:
        shift = (mask & -mask).bit_length() - 1
        channels.append(((value & mask) >> shift).astype(numpy.uint8))
    return numpy.dstack(channels)


def write_png(path, rgb):
    height, width, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[y].tobytes() for y in range(height))

    def chunk(kind, payload):
        return (struct.pack(">I", len(payload)) + kind + payload +
                struct.pack(">I", zlib.crc32(kind + payload) & 0xFFFFFFFF))

    with open(path, "wb") as out:
        out.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
                  chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def render_view_box(rgb):
    """The bounding box (x0, x1, y0, y1) of the render view's background in a screen picture."""
    background = numpy.all(numpy.abs(rgb.astype(int) - BACKGROUND) <= 6, axis=2)
    ys, xs = numpy.nonzero(background)
    if len(xs) < 10000:
        raise RuntimeError("no render view background found on the screen")
    return xs.min(), xs.max(), ys.min(), ys.max()


def start_xvfb(width, height):
    read, write = os.pipe()
    xvfb = subprocess.Popen(["Xvfb", "-displayfd", str(write), "-screen", "0", "%dx%dx24" % (width, height),
                             "-nolisten", "tcp", "-noreset"], pass_fds=[write], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    os.close(write)
    with os.fdopen(read) as pipe:
        display = pipe.readline().strip()
    if not display:
        xvfb.kill()
        raise RuntimeError("Xvfb did not start")
    return xvfb, ":" + display


def wait_for(path, seconds, process):
    deadline = time.time() + seconds
    while time.time() < deadline:
        if os.path.exists(path):
            return True
        if process.poll() is not None:
            return False
        time.sleep(0.2)
    return False


def press_p_over_the_view(env, workdir):
    """Enlarges and focuses ParaView's window, then presses P with the mouse in the middle of
    the render view (found by its background colour)."""
    windows = subprocess.run(["xdotool", "search", "--onlyvisible", "--name", "ParaView [0-9]"], env=env,
                             capture_output=True, text=True).stdout.split()
    if not windows:
        raise RuntimeError("no ParaView window on the display")
    subprocess.run(["xdotool", "windowsize", windows[0], "1600", "1000", "windowfocus", windows[0]],
                   env=env, check=True)
    time.sleep(2)
    dump = os.path.join(workdir, "before-pick.xwd")
    subprocess.run(["xwd", "-root", "-silent", "-out", dump], env=env, check=True)
    x0, x1, y0, y1 = render_view_box(read_xwd(dump))
    x, y = (x0 + x1) // 2, (y0 + y1) // 2
    subprocess.run(["xdotool", "mousemove", str(x), str(y)], env=env, check=True)
    time.sleep(0.5)
    subprocess.run(["xdotool", "key", "p"], env=env, check=True)
    return x, y


def main():
    parser = argparse.ArgumentParser()
    for name in ("--paraview", "--plugin-dir", "--workdir"):
        parser.add_argument(name, required=True)
    args = parser.parse_args()
    workdir = os.path.abspath(args.workdir)
    shutil.rmtree(workdir, ignore_errors=True)
    os.makedirs(workdir)
    with open(os.path.join(HERE, "TestGUI.xml")) as template:
        events = template.read().replace("@WORKDIR@", workdir)
    events = events.replace("@CHECKS@", rgmc_testing.in_paraview("GUIChecks.py"))
    events = events.replace("@READY@", rgmc_testing.in_paraview("GUIReady.py"))
    script = os.path.join(workdir, "TestGUI.xml")
    with open(script, "w") as out:
        out.write(events)

    failures = []
    xvfb, display = start_xvfb(1600, 1000)
    paraview = None
    try:
        env = dict(os.environ, DISPLAY=display, PV_PLUGIN_PATH=args.plugin_dir)
        env.pop("PV_PLUGIN_CONFIG_FILE", None)
        log = open(os.path.join(workdir, "paraview.log"), "w")
        paraview = subprocess.Popen([args.paraview, "--dr", "--test-script=" + script, "--exit"], env=env,
                                    stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
        if not wait_for(os.path.join(workdir, "ready"), 180, paraview):
            failures.append("the playback never showed the surface (see paraview.log)")
        else:
            x, y = press_p_over_the_view(env, workdir)
            print("pressed P at (%d, %d)" % (x, y))
        status = paraview.wait(timeout=300)
        if status != 0:
            failures.append("paraview's test playback failed with status %d (see paraview.log)" % status)
    finally:
        if paraview is not None and paraview.poll() is None:
            os.killpg(paraview.pid, signal.SIGKILL)
        xvfb.kill()
        xvfb.wait()

    print(open(os.path.join(workdir, "paraview.log")).read()[-3000:])
    checks_path = os.path.join(workdir, "checks.json")
    if not os.path.exists(checks_path):
        failures.append("GUIChecks.py wrote nothing")
    else:
        results = json.load(open(checks_path))
        print(json.dumps(results, indent=1))
        if "error" in results:
            failures.append("GUIChecks.py failed: " + results["error"])
        else:
            seeds = results["seeds"]
            spacing = min(results["spacing"])
            if len(seeds) != 6 or seeds[:3] != [0.0, 0.0, 105.0]:
                failures.append("SeedPoints are %s, not the typed seed (0, 0, 105) and a picked one" % seeds)
            elif max(abs(a - b) for a, b in zip(seeds[:3], seeds[3:])) == 0:
                failures.append("P did not move the handle: the second seed equals the first")
            elif results["seed_distances"][1] > 1e-3 * spacing:
                failures.append("the seed placed with P is %g from the surface, not on it" % results["seed_distances"][1])
            if results["triangles"] != results["oracle_triangles"] or results["triangles"] == 0:
                failures.append("the GUI's surface has %d triangles, the oracle's %d" % (
                    results["triangles"], results["oracle_triangles"]))
            if results["visible"] != 1 or results["representation"] != "Surface":
                failures.append("the surface is not shown as a surface (visible %s, %s)" % (
                    results["visible"], results["representation"]))
            # The skull seen from above covers about 7% of the view; the orientation axes, the only
            # other thing drawn, under 0.5%.
            if results["surface_pixel_fraction"] < 0.02:
                failures.append("the surface covers only %.1f%% of the render view" % (
                    100 * results["surface_pixel_fraction"]))
        window = os.path.join(workdir, "window.xwd")
        if os.path.exists(window):
            picture = read_xwd(window)
            write_png(os.path.join(workdir, "paraview-window.png"), picture)
            x0, x1, y0, y1 = render_view_box(picture)
            view = picture[y0:y1 + 1, x0:x1 + 1].astype(int)
            covered = numpy.mean(numpy.abs(view - BACKGROUND).max(axis=2) > 24)
            print("window picture %dx%d, render view %dx%d, %.1f%% of it not background" % (
                picture.shape[1], picture.shape[0], x1 - x0 + 1, y1 - y0 + 1, 100 * covered))
            if covered < 0.02:
                failures.append("the window picture's render view shows no surface")
        else:
            failures.append("no picture of the window was taken")
    for failure in failures:
        print("FAILED: " + failure, file=sys.stderr)
    if not failures:
        print("TestGUI: the seed placed with the handle and P gives the oracle's surface, shown in the render view")
    return 1 if failures else 0


sys.exit(main())
