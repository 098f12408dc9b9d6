"""Runs inside the ParaView GUI, in its Python shell (TestGUI.xml executes it with WORKDIR set):
records what the GUI holds and shows after the user's session, for TestGUI.py to judge.

Writes WORKDIR/checks.json (the seeds and triangles of the filter made through the menus, the
oracle's triangle count, each seed's distance to the surface, the display's state, how much of
the render view the surface covers) and WORKDIR/window.xwd (the whole screen, which the main
window fills).
"""

import json
import os
import subprocess

import numpy
from paraview import servermanager
from paraview.simple import FindSource, GetActiveView, GetDisplayProperties, Hide, Render, SaveScreenshot, Show
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkFiltersCore import (vtkImplicitPolyDataDistance, vtkMarchingCubes,
                                       vtkPolyDataConnectivityFilter)
from vtkmodules.vtkIOImage import vtkPNGReader


def view_pixels(view, path):
    SaveScreenshot(path, view, ImageResolution=[800, 600])
    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    return vtk_to_numpy(image.GetPointData().GetScalars()).astype(int)


def checks(workdir):
    results = {}
    # The whole window first, as the user sees it now.
    subprocess.run(["xwd", "-root", "-silent", "-out", os.path.join(workdir, "window.xwd")], check=True)

    surface = FindSource("RegionGrowingMarchingCubes1")
    phantom = FindSource("CTPhantom1")
    results["seeds"] = list(surface.SeedPoints)
    results["isovalue"] = surface.Isovalue
    results["triangles"] = surface.GetDataInformation().GetNumberOfCells()

    # The oracle: VTK's marching cubes and connectivity (closest point region) on the same
    # volume, from the first seed.
    volume = servermanager.Fetch(phantom)
    mc = vtkMarchingCubes()
    mc.SetInputData(volume)
    mc.SetValue(0, surface.Isovalue)
    mc.ComputeNormalsOff()
    mc.ComputeScalarsOff()
    connectivity = vtkPolyDataConnectivityFilter()
    connectivity.SetInputConnection(mc.GetOutputPort())
    connectivity.SetExtractionModeToClosestPointRegion()
    connectivity.SetClosestPoint(results["seeds"][:3])
    connectivity.Update()
    results["oracle_triangles"] = connectivity.GetOutput().GetNumberOfCells()

    # Where the seeds are relative to the extracted surface.
    mesh = servermanager.Fetch(surface)
    distance = vtkImplicitPolyDataDistance()
    distance.SetInput(mesh)
    seeds = results["seeds"]
    results["seed_distances"] = [abs(distance.EvaluateFunction(seeds[i:i + 3])) for i in range(0, len(seeds), 3)]
    results["spacing"] = list(volume.GetSpacing())

    # What the render view shows: the surface's display, and the pixels it covers.
    view = GetActiveView()
    display = GetDisplayProperties(surface, view)
    results["visible"] = int(display.Visibility)
    results["representation"] = display.SMProxy.GetProperty("Representation").GetElement(0)
    shown = view_pixels(view, os.path.join(workdir, "view-with-surface.png"))
    Hide(surface, view)
    hidden = view_pixels(view, os.path.join(workdir, "view-without-surface.png"))
    Show(surface, view)
    Render(view)
    results["surface_pixel_fraction"] = float(numpy.mean(numpy.abs(shown - hidden).max(axis=1) > 24))
    return results


try:
    output = checks(WORKDIR)  # noqa: F821 (given by TestGUI.xml)
except Exception as error:  # reported to the driver, which fails the test with it
    output = {"error": "%s: %s" % (type(error).__name__, error)}
with open(os.path.join(WORKDIR, "checks.json"), "w") as out:  # noqa: F821
    json.dump(output, out, indent=1)
