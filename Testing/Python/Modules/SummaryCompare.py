"""Compares a PluginSummary.py result with the 1-rank pvbatch one: used by TestPluginMPI.py
(pvbatch under mpiexec) and TestClientServer.py (a pvpython client of an MPI pvserver)."""

EXTRACTIONS = ("skull", "skull+jaw+vertebra", "largest", "all")
REPAIRS = ("repaired Laplacian", "repaired Windowed Sinc")


def compare(summary, reference, ranks, where):
    """The failures of `summary` (from `where`, on `ranks` ranks) against the 1-rank `reference`,
    as messages; none when every surface is exactly the 1-rank one."""
    failures = []
    if summary["ranks"] != ranks:
        failures.append("%s ran on %d ranks, not %d" % (where, summary["ranks"], ranks))
    for run in EXTRACTIONS:
        ours, theirs = summary[run], reference[run]
        for field in ("triangles", "vertices", "digest", "number_of_triangles_field"):
            if ours[field] != theirs[field]:
                failures.append("%s, %s: %s %s, on 1 rank %s" % (where, run, field, ours[field], theirs[field]))
        if ours["number_of_triangles_field"] != [theirs["triangles"]] * 2:
            failures.append("%s, %s: NumberOfTriangles %s" % (where, run, ours["number_of_triangles_field"]))
        if ranks > 1 and len(ours["ranks_with_triangles"]) < 2:
            failures.append("%s, %s: only ranks %s made triangles" % (where, run, ours["ranks_with_triangles"]))
    for run in REPAIRS:
        ours, theirs = summary[run], reference[run]
        if ours != theirs:
            failures.append("%s, %s differs from 1 rank: %s vs %s" % (where, run, ours, theirs))
        if ours["Closed"] != 1 or ours["EulerCharacteristic"] != -6:
            failures.append("%s, %s: not a closed skull: %s" % (where, run, ours))
        if not (ours["ply_vertices"] == ours["UniquePoints"] == ours["vertices"] == ours["max_gid"] + 1):
            failures.append("%s, %s: PLY vertices %d, unique points %d, global ids %d" % (
                where, run, ours["ply_vertices"], ours["UniquePoints"], ours["vertices"]))
    return failures
