"""Runs inside the ParaView GUI, in its Python shell (TestGUI.xml executes it with WORKDIR set),
once the surface is shown: gives the render view one solid background colour, ParaView 5.11's
default, on every version (6.0 changed the default background), so that TestGUI.py can find the
view on the screen by its colour; then tells TestGUI.py that the GUI is ready for the P key."""

import os

from paraview.simple import GetActiveView, Render

view = GetActiveView()
# Each property exists on some versions only: set those this ParaView has.
for name, value in (("UseColorPaletteForBackground", 0), ("BackgroundColorMode", "Single Color"),
                    ("Background", [0.32, 0.34, 0.43])):
    try:
        setattr(view, name, value)
    except (AttributeError, ValueError):
        pass
Render(view)
open(os.path.join(WORKDIR, "ready"), "w").close()  # noqa: F821 (given by TestGUI.xml)
