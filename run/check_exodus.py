#!/usr/bin/python3
"""Check an Exodus II file the solver wrote against its HDF5 result, independently of the
solver's own code: netCDF4 reads the .e, h5py the .h5, and every array must hold the same
bits (float64 compared as their 64-bit patterns, so -0.0 and NaN would not pass as equal).

Usage: /usr/bin/python3 run/check_exodus.py RESULT.e RESULT.h5

Checks the mesh (coordinates, the number maps against /mesh/node_ids and the bodies'
element ids, each block's connectivity and name, node sets and side sets by name), the
time values, every nodal and element variable at every step, and the global variables
against /stats. Prints one line per array kind with the count compared, then
"exodus check: N arrays bitwise equal". Exit 0 when all are equal, 1 on a difference,
2 when a file cannot be read.

Needs Debian's python3-netcdf4 and python3-h5py (run/setup) for /usr/bin/python3.
"""

import sys

try:
    import h5py
    import netCDF4
    import numpy as np
except ImportError as e:  # pragma: no cover - reported, not tested
    print(f"check_exodus: {e}; install python3-netcdf4 and python3-h5py (run/setup)",
          file=sys.stderr)
    sys.exit(2)

NODAL = {"displ": "/results/displacement", "reaction": "/results/reaction",
         "contact_force": "/results/contact/force"}
SCALAR_NODAL = {"contact_status": "/results/contact/status",
                "contact_gap": "/results/contact/gap",
                "contact_pressure": "/results/contact/pressure"}
STRESS = ["xx", "yy", "zz", "xy", "yz", "zx"]
GLOBAL = ["cg_iterations", "contact_updates", "residual", "cutbacks", "contact_active",
          "contact_stick", "contact_slip", "contact_released", "max_penetration"]


class Checker:
    def __init__(self):
        self.count = 0
        self.failures = []

    def same(self, what, a, b):
        """a from the .e, b from the .h5: same shape and the same bits as float64 or int64."""
        a, b = np.asarray(a), np.asarray(b)
        self.count += 1
        if a.shape != b.shape:
            self.failures.append(f"{what}: shape {a.shape} in .e, {b.shape} in .h5")
            return
        if a.dtype.kind == "f" or b.dtype.kind == "f":
            equal = np.array_equal(a.astype(np.float64).view(np.uint64),
                                   b.astype(np.float64).view(np.uint64))
        else:
            equal = np.array_equal(a.astype(np.int64), b.astype(np.int64))
        if not equal:
            self.failures.append(f"{what}: values differ")


def names(var):
    return [str(s) for s in netCDF4.chartostring(var[:])]


def check_mesh(e, h, c):
    coords = h["/mesh/coordinates"][:]
    for k, axis in enumerate("xyz"):
        c.same(f"coord{axis}", e["coord" + axis][:], coords[:, k])
    c.same("node_num_map", e["node_num_map"][:], h["/mesh/node_ids"][:])
    blocks = names(e["eb_names"])
    elem_ids = []
    for b, name in enumerate(blocks):
        g = h["/mesh/" + name]
        c.same(f"connect{b + 1} ({name})", e[f"connect{b + 1}"][:] - 1, g["connectivity"][:])
        if e[f"connect{b + 1}"].elem_type != "HEX8":
            c.failures.append(f"connect{b + 1}: elem_type {e[f'connect{b + 1}'].elem_type}")
        elem_ids.append(g["element_ids"][:])
    elem_ids = np.concatenate(elem_ids) if elem_ids else np.zeros(0, np.int64)
    c.same("elem_num_map", e["elem_num_map"][:], elem_ids)
    node_ids = h["/mesh/node_ids"][:]
    if "ns_names" in e.variables:
        for s, name in enumerate(names(e["ns_names"])):
            c.same(f"node set {name}", node_ids[e[f"node_ns{s + 1}"][:] - 1],
                   h["/mesh/node_sets/" + name][:])
    if "ss_names" in e.variables:
        for s, name in enumerate(names(e["ss_names"])):
            faces = h["/mesh/side_sets/" + name][:]
            c.same(f"side set {name} elements", elem_ids[e[f"elem_ss{s + 1}"][:] - 1],
                   faces[:, 0])
            c.same(f"side set {name} sides", e[f"side_ss{s + 1}"][:] - 1, faces[:, 1])
    return blocks


def check_steps(e, h, blocks, c):
    c.same("time_whole", e["time_whole"][:], h["/results/time"][:])
    nodal = names(e["name_nod_var"])
    for v, name in enumerate(nodal):
        values = e[f"vals_nod_var{v + 1}"][:]
        base, _, axis = name.rpartition("_")
        if base in NODAL:
            ref = h[NODAL[base]][:, :, "xyz".index(axis)]
        else:
            ref = h[SCALAR_NODAL[name]][:]
        c.same(f"nodal {name}", values, ref)
    sizes = [h["/mesh/" + b]["connectivity"].shape[0] for b in blocks]
    first = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
    for v, name in enumerate(names(e["name_elem_var"])):
        if name == "eqps":
            ref = h["/results/plastic_strain"][:]
        else:
            ref = h["/results/stress"][:, :, STRESS.index(name.removeprefix("stress_"))]
        for b in range(len(blocks)):
            c.same(f"element {name} block {blocks[b]}", e[f"vals_elem_var{v + 1}eb{b + 1}"][:],
                   ref[:, first[b]:first[b + 1]])
    glo = e["vals_glo_var"][:]
    if names(e["name_glo_var"]) != GLOBAL:
        c.failures.append(f"global variables {names(e['name_glo_var'])}")
    for k, name in enumerate(GLOBAL):
        c.same(f"global {name}", glo[:, k], h["/stats/" + name][:])
    return nodal


def main(argv):
    if len(argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    try:
        e = netCDF4.Dataset(argv[1])
        e.set_auto_mask(False)
        h = h5py.File(argv[2], "r")
    except OSError as err:
        print(f"check_exodus: {err}", file=sys.stderr)
        return 2
    c = Checker()
    blocks = check_mesh(e, h, c)
    nodal = check_steps(e, h, blocks, c)
    print(f"format {e.file_format}, title {e.title!r}, {len(e.dimensions['num_nodes'])} nodes, "
          f"{len(e.dimensions['num_elem'])} elements, blocks {blocks}, "
          f"{len(e.dimensions['time_step'])} steps, nodal variables {nodal}")
    for f in c.failures:
        print("DIFFERS:", f)
    print(f"exodus check: {c.count - len(c.failures)} of {c.count} arrays bitwise equal")
    return 1 if c.failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
