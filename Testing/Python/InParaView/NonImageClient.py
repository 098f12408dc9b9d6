"""pvpython client for TestClientServer.py: the filter on a non-image input, on a pvserver, must
fail with VTK's message naming the required type (the GUI does not offer it for such input)."""

import sys

from paraview import simple

host, port, plugin = sys.argv[1], int(sys.argv[2]), sys.argv[3]
if simple.Connect(host, port) is None:
    sys.exit("cannot connect")
simple.LoadPlugin(plugin, remote=False, ns=vars(simple))
simple.LoadPlugin(plugin, remote=True, ns=vars(simple))
sphere = simple.Sphere()
surface = simple.RGMarchingCubes(Input=sphere, Isovalue=0.5, SeedPoints=[0, 0, 0.5])
surface.UpdatePipeline()
print("triangles from a sphere's polydata: %d" % surface.GetDataInformation().GetNumberOfCells())
