"""Each of the plugin's shared objects calls the functions it defines itself: no PLT relocation
(`readelf -r`: a JUMP_SLOT) names a function the same object exports (`nm -D --defined-only`).

A call through the PLT goes to whichever copy the loader found first in the process. For the
templates a library instantiates (std::vector<int>::push_back, ...) that is often another
library's: in Debian 12's pvpython it was libvtkprotobuf's, compiled without inlining, under the
extraction's innermost loop. The plugin links with -Bsymbolic-functions (CMakeLists.txt), which
binds those calls at link time; this test fails when that flag is lost.

The same check on a control linked without it (VTK's CommonCore, with thousands of such calls)
must find some: otherwise the test itself is broken (a tool that prints nothing, a pattern that
matches nothing) and says so.

  python3 TestOwnCalls.py --readelf readelf --nm nm --plugin-dir DIR [--module LIB] --control LIB
"""

import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Modules"))
import rgmc_testing  # noqa: E402

SECTION = re.compile(r"^Relocation section '([^']+)'")


def plt_functions(readelf, path):
    """The symbols of the object's PLT relocations (its calls the loader binds)."""
    out = subprocess.run([readelf, "-r", "-W", path], capture_output=True, text=True,
                         check=True).stdout
    names, section = set(), ""
    for line in out.splitlines():
        match = SECTION.match(line)
        if match:
            section = match.group(1)
            continue
        fields = line.split()
        if section.endswith(".plt") and len(fields) >= 5 and "JUMP_SLOT" in fields[2]:
            names.add(fields[4].split("@")[0])
    return names


def defined_functions(nm, path):
    """The functions the object exports: text (T), weak (W, the templates) and indirect (i)."""
    out = subprocess.run([nm, "-D", "--defined-only", path], capture_output=True, text=True,
                         check=True).stdout
    names = set()
    for line in out.splitlines():
        fields = line.split()
        if len(fields) == 3 and fields[1] in ("T", "W", "i"):
            names.add(fields[2].split("@")[0])
    return names


def own_calls_through_plt(readelf, nm, path):
    plt = plt_functions(readelf, path)
    defined = defined_functions(nm, path)
    return sorted(plt & defined), len(plt), len(defined)


def main():
    args, objects = rgmc_testing.linkage_arguments()
    if objects is None:
        return 1
    failures = 0
    for path in objects:
        own, plt, defined = own_calls_through_plt(args.readelf, args.nm, path)
        print("%s: %d PLT calls, %d functions defined, %d own functions called through the PLT %s"
              % (os.path.basename(path), plt, defined, len(own), own[:5]))
        # An object that calls nothing and defines nothing was not read at all.
        if plt == 0 or defined == 0:
            print("FAILED: %s: readelf or nm read nothing" % path)
            failures += 1
        if own:
            print("FAILED: %s calls %d of its own functions through the PLT (another library's "
                  "copy may be taken): linked without -Bsymbolic-functions?" % (path, len(own)))
            failures += 1
    own, plt, _ = own_calls_through_plt(args.readelf, args.nm, args.control)
    print("control %s: %d PLT calls, %d to its own functions (e.g. %s)"
          % (os.path.basename(args.control), plt, len(own), own[:3]))
    if not own:
        print("FAILED: the check finds no own call through the PLT in the control %s, which makes "
              "them" % args.control)
        failures += 1
    return 1 if failures else 0


sys.exit(main())
