"""The plugin is free of any one MPI: none of its shared objects needs an MPI library
(`readelf -d`: no NEEDED libmpi*, libmpich*, libopen-rte*, libopen-pal*, libpmix*) or leaves an
MPI symbol for the loader to find (`nm -D --undefined-only`: no MPI_*, PMPI_*, ompi_*). All its
communication goes through vtkMultiProcessController, so the same source builds and runs against
Debian's Open MPI ParaView and Kitware's MPICH binaries alike; one direct MPI call, or a header
that inlines MPI (DIY's, for example), would tie it to one implementation, and this test fails.

The same check run on a control that does use MPI (VTK's ParallelMPI library, given with
--control) must find it: otherwise the test itself is broken (a tool that prints nothing, a
pattern that matches nothing) and says so.

  python3 TestNoMPI.py --readelf readelf --nm nm --plugin-dir DIR [--module LIB] --control LIB
"""

import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Modules"))
import rgmc_testing  # noqa: E402

MPI_LIBRARY = re.compile(r"^lib(mpi|mpich|open-rte|open-pal|pmix)[^/]*\.so")
MPI_SYMBOL = re.compile(r"^(P?MPI_|ompi_|MPIR_)")


def mpi_libraries(readelf, path):
    """The MPI libraries among the object's NEEDED entries, and how many entries there are."""
    out = subprocess.run([readelf, "-d", "-W", path], capture_output=True, text=True, check=True).stdout
    needed = re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", out)
    return [n for n in needed if MPI_LIBRARY.match(n)], len(needed)


def mpi_symbols(nm, path):
    """The MPI symbols the object leaves undefined, and how many undefined symbols it has."""
    out = subprocess.run([nm, "-D", "--undefined-only", path], capture_output=True, text=True,
                         check=True).stdout
    names = [line.split()[-1] for line in out.splitlines() if line.strip()]
    names = [n.split("@")[0] for n in names]
    return sorted(n for n in names if MPI_SYMBOL.match(n)), len(names)


def main():
    args, objects = rgmc_testing.linkage_arguments()
    if objects is None:
        return 1
    failures = 0
    for path in objects:
        libraries, needed = mpi_libraries(args.readelf, path)
        symbols, undefined = mpi_symbols(args.nm, path)
        print("%s: %d needed libraries, %d undefined symbols; MPI: %s %s"
              % (os.path.basename(path), needed, undefined, libraries or "no library,",
                 symbols[:10] or "no symbol"))
        # An object that needs nothing and leaves nothing undefined was not read at all.
        if needed == 0 or undefined == 0:
            print("FAILED: %s: readelf or nm read nothing" % path)
            failures += 1
        if libraries or symbols:
            print("FAILED: %s is tied to one MPI: needs %s, leaves undefined %s"
                  % (path, libraries, symbols[:10]))
            failures += 1
    # The control: a library that is built on MPI must be found out by the same check.
    libraries, _ = mpi_libraries(args.readelf, args.control)
    symbols, _ = mpi_symbols(args.nm, args.control)
    print("control %s: MPI libraries %s, %d MPI symbols (e.g. %s)"
          % (os.path.basename(args.control), libraries, len(symbols), symbols[:3]))
    if not libraries or not symbols:
        print("FAILED: the check does not see MPI in the control %s, which uses it" % args.control)
        failures += 1
    return 1 if failures else 0


sys.exit(main())
