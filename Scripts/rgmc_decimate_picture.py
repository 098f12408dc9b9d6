"""The picture of README's decimation section: a skull as extracted and repaired (left) and
decimated to a tenth by Decimate Surface (right), triangle edges drawn, seen from the front and
close up on the face.

  pvbatch Scripts/rgmc_decimate_picture.py --output docs/decimate-skull.png \
      --input build/demo/cranium-dicom --isovalue 299.5 --seed 126.3,103.4,155.8

(the demo's real head CT; the defaults are the CT phantom at 256^3, 400 HU, seed 0,0,105).
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rgmc_common  # noqa: E402


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--output", required=True, help="the PNG to write")
    parser.add_argument("--input", default="phantom:256",
                        help="a volume, as the pipeline command reads it (default phantom:256)")
    parser.add_argument("--isovalue", type=float, default=400)
    parser.add_argument("--seed", default="0,0,105", help="x,y,z in world coordinates")
    parser.add_argument("--reduction", type=float, default=0.9)
    parser.add_argument("--plugin", help="the plugin library (default: found in build/)")
    args = parser.parse_args(argv)
    from paraview import simple
    rgmc_common.load_plugin(args.plugin)
    volume = rgmc_common.open_volume(args.input)
    volume.UpdatePipeline()
    array = [a for a in rgmc_common.image_summary(volume)[2] if a[1] == 1][0][0]
    skull = simple.RGMarchingCubes(Input=volume, ContourBy=["POINTS", array],
                                   Isovalue=args.isovalue,
                                   SeedPoints=[float(x) for x in args.seed.split(",")])
    repaired = simple.SeamRepair(Input=skull)
    decimated = simple.RGDecimate(Input=repaired, TargetReduction=args.reduction)
    decimated.UpdatePipeline()
    before = repaired.GetDataInformation().GetNumberOfCells()
    after = decimated.GetDataInformation().GetNumberOfCells()
    layout = simple.CreateLayout("decimation")
    views = []
    for index, source in enumerate((repaired, decimated)):
        view = simple.CreateRenderView()
        simple.AssignViewToLayout(view=view, layout=layout, hint=index)
        view.OrientationAxesVisibility = 0
        view.Background = [0.11, 0.12, 0.15]
        try:
            view.UseColorPaletteForBackground = 0
        except AttributeError:
            pass
        display = simple.Show(source, view)
        display.SetRepresentationType("Surface With Edges")
        display.DiffuseColor = [0.93, 0.87, 0.74]
        display.EdgeColor = [0.25, 0.2, 0.15]
        # From the front (+y, a CT's face), close enough to see the triangles.
        bounds = repaired.GetDataInformation().GetBounds()
        centre = [(bounds[2 * a] + bounds[2 * a + 1]) / 2 for a in range(3)]
        size = max(bounds[2 * a + 1] - bounds[2 * a] for a in range(3))
        view.CameraFocalPoint = [centre[0], bounds[3], centre[2]]
        view.CameraPosition = [centre[0] + 0.5 * size, bounds[3] + 1.6 * size, centre[2] + 0.3 * size]
        view.CameraViewUp = [0, 0, 1]
        view.CameraViewAngle = 24
        text = simple.Text(Text="%s: %d triangles" % (
            "extracted and repaired" if index == 0 else "decimated to %g%%" % (
                100 * (1 - args.reduction)), before if index == 0 else after))
        label = simple.Show(text, view)
        label.FontSize = 15
        label.WindowLocation = "Upper Left Corner"
        views.append(view)
    simple.SaveScreenshot(args.output, layout, ImageResolution=[1600, 700])
    print("written: %s (%d and %d triangles)" % (args.output, before, after))
    return 0


if __name__ == "__main__":
    rgmc_common.run(main, "rgmc_decimate_picture")
