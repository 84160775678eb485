#!/usr/bin/python3
"""Check a solver result file independently of the solver's own reader.

Usage: /usr/bin/python3 run/check_h5.py RESULT.h5

Prints every dataset with its shape and dtype and every root attribute, then checks the
documented layout (README.md, "Result files"): the datasets and attributes that must be
there, their dtypes, and that node, element and step counts agree between datasets.
Exits 0 when the file is consistent, 1 on any mismatch, 2 when it cannot be read.

Needs h5py: Debian's python3-h5py (installed by run/setup) for /usr/bin/python3.
"""

import sys

try:
    import h5py
    import numpy as np
except ImportError as e:  # pragma: no cover - reported, not tested
    print(f"check_h5: {e}; install python3-h5py (run/setup) and use /usr/bin/python3",
          file=sys.stderr)
    sys.exit(2)

REQUIRED_ATTRIBUTES = ["format_version", "solver_version", "ranks", "scene", "scene_name",
                       "units", "start_time", "exit_status"]
# "wall_time" is written when the run ends; a .tmp file of a run under way lacks it.


def main(argv):
    if len(argv) != 2:
        print("usage: check_h5.py RESULT.h5", file=sys.stderr)
        return 2
    path = argv[1]
    try:
        f = h5py.File(path, "r")
    except (OSError, ValueError) as e:
        print(f"check_h5: {path}: cannot open as HDF5: {e}", file=sys.stderr)
        return 2

    problems = []
    try:
        return check(f, path, problems)
    except OSError as e:  # a checksum that fails, a damaged file
        problems.append(f"reading failed: {e}")
        return report(problems)


def check(f, path, problems):

    def problem(msg):
        problems.append(msg)

    with f:
        datasets = {}

        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                datasets["/" + name] = obj

        f.visititems(visit)
        print(f"{path}: {len(datasets)} datasets")
        for name in sorted(datasets):
            d = datasets[name]
            print(f"  {name:40s} shape={d.shape} dtype={d.dtype}")
        print("attributes:")
        for key in sorted(f.attrs):
            value = f.attrs[key]
            text = value.decode() if isinstance(value, bytes) else str(value)
            text = text.replace("\n", "\\n")
            if len(text) > 60:
                text = text[:57] + "..."
            print(f"  {key:16s} {text}")

        for key in REQUIRED_ATTRIBUTES:
            if key not in f.attrs:
                problem(f"missing root attribute {key}")
        status = f.attrs.get("exit_status", b"")
        status = status.decode() if isinstance(status, bytes) else str(status)
        if status != "running" and "wall_time" not in f.attrs:
            problem("missing root attribute wall_time")
        if not (status in ("completed", "running") or status.startswith("failed: ")):
            problem(f"exit_status {status!r} is not completed, running or failed: ...")

        def get(name, kind, ndim):
            d = datasets.get(name)
            if d is None:
                problem(f"missing dataset {name}")
                return None
            if d.dtype.kind != kind[0] or d.dtype.itemsize != int(kind[1:]):
                problem(f"{name}: dtype {d.dtype}, expected {kind}")
            if d.ndim != ndim:
                problem(f"{name}: {d.ndim} dimensions, expected {ndim}")
                return None
            return d

        def expect(name, shape, text):
            d = datasets.get(name)
            if d is None:
                return
            ok = d.ndim == len(shape) and all(
                want is None or want == got for want, got in zip(shape, d.shape))
            if not ok:
                problem(f"{name}: shape {d.shape}, expected {text}")

        coords = get("/mesh/coordinates", "f8", 2)
        conn = get("/mesh/all_connectivity", "u8", 2)
        time = get("/results/time", "f8", 1)
        if coords is None or conn is None or time is None:
            return report(problems)
        nodes, elements, steps = coords.shape[0], conn.shape[0], time.shape[0]
        print(f"nodes {nodes}, elements {elements}, steps {steps}")
        expect("/mesh/coordinates", (None, 3), "[nodes, 3]")
        expect("/mesh/all_connectivity", (None, 8), "[elements, 8]")

        node_ids = get("/mesh/node_ids", "u8", 1)
        expect("/mesh/node_ids", (nodes,), f"[{nodes}]")
        per_step = [
            ("/results/displacement", "f8", (steps, nodes, 3)),
            ("/results/stress", "f8", (steps, elements, 6)),
            ("/results/reaction", "f8", (steps, nodes, 3)),
            ("/results/contact/force", "f8", (steps, nodes, 3)),
            ("/results/contact/status", "u1", (steps, nodes)),
            ("/results/contact/gap", "f8", (steps, nodes)),
            ("/stats/cg_iterations", "u8", (steps,)),
            ("/stats/contact_updates", "u8", (steps,)),
            ("/stats/residual", "f8", (steps,)),
            ("/stats/wall_time", "f8", (steps,)),
            ("/stats/cutbacks", "u8", (steps,)),
            ("/stats/contact_active", "u8", (steps,)),
            ("/stats/contact_stick", "u8", (steps,)),
            ("/stats/contact_slip", "u8", (steps,)),
            ("/stats/contact_released", "u8", (steps,)),
            ("/stats/max_penetration", "f8", (steps,)),
        ]
        for name, kind, shape in per_step:
            if get(name, kind, len(shape)) is not None:
                expect(name, shape, str(list(shape)))
        # Optional: files written before the contact pressure was recorded lack it.
        optional = [("/results/contact/pressure", "f8", (steps, nodes))]
        for name, kind, shape in optional:
            if name in datasets and get(name, kind, len(shape)) is not None:
                expect(name, shape, str(list(shape)))
        if get("/partition/element_rank", "u4", 1) is not None:
            expect("/partition/element_rank", (elements,), f"[{elements}]")

        # Bodies: every group in /mesh other than the set groups.
        body_elements = 0
        ids = set()
        all_conn = conn[...]
        bodies = []
        for name, obj in f["/mesh"].items():
            if not isinstance(obj, h5py.Group) or name in ("node_sets", "side_sets"):
                continue
            c = get(f"/mesh/{name}/connectivity", "u8", 2)
            e = get(f"/mesh/{name}/element_ids", "u8", 1)
            if c is None or e is None:
                continue
            expect(f"/mesh/{name}/connectivity", (None, 8), "[elements, 8]")
            expect(f"/mesh/{name}/element_ids", (c.shape[0],), f"[{c.shape[0]}]")
            first = int(obj.attrs.get("first_element", -1))
            bodies.append((int(obj.attrs.get("body_index", -1)), name, first, c[...]))
            body_elements += c.shape[0]
            ids.update(int(i) for i in e[...])
        if body_elements != elements:
            problem(f"bodies hold {body_elements} elements, /mesh/all_connectivity {elements}")
        else:
            start = 0
            for _, name, first, c in sorted(bodies):
                if first != start:
                    problem(f"/mesh/{name}: first_element {first}, expected {start}")
                if c.size and not np.array_equal(c, all_conn[start:start + c.shape[0]]):
                    problem(f"/mesh/{name}/connectivity differs from its rows in "
                            "/mesh/all_connectivity")
                start += c.shape[0]
        if all_conn.size and int(all_conn.max()) >= nodes:
            problem(f"/mesh/all_connectivity refers to node index {int(all_conn.max())} "
                    f"of {nodes}")
        if "/mesh/node_sets" not in f or "/mesh/side_sets" not in f:
            problem("missing group /mesh/node_sets or /mesh/side_sets")
        else:
            known = set(int(i) for i in node_ids[...]) if node_ids is not None else set()
            for name, d in f["/mesh/node_sets"].items():
                if d.ndim != 1 or d.dtype != np.uint64:
                    problem(f"/mesh/node_sets/{name}: shape {d.shape} dtype {d.dtype}, "
                            "expected [n] uint64")
                elif not set(int(i) for i in d[...]) <= known:
                    problem(f"/mesh/node_sets/{name} names node ids not in /mesh/node_ids")
            for name, d in f["/mesh/side_sets"].items():
                if d.ndim != 2 or d.shape[1] != 2 or d.dtype != np.uint64:
                    problem(f"/mesh/side_sets/{name}: shape {d.shape} dtype {d.dtype}, "
                            "expected [n, 2] uint64")
                    continue
                v = d[...]
                if v.size and int(v[:, 1].max()) > 5:
                    problem(f"/mesh/side_sets/{name} has a local face above 5")
                if not set(int(i) for i in v[:, 0]) <= ids:
                    problem(f"/mesh/side_sets/{name} names element ids no body has")

        # No NaN or infinity anywhere.
        for name, d in datasets.items():
            if d.dtype.kind == "f" and d.size and not np.all(np.isfinite(d[...])):
                problem(f"{name} holds NaN or infinite values")
        # Format 2: every dataset with data carries a Fletcher-32 checksum (h5py checks it
        # on every read, so the reads above and below have checked them all), and the
        # restart state is in two slots.
        version = int(f.attrs.get("format_version", 0))
        if version >= 2:
            for name, d in datasets.items():
                if d.size and not d.fletcher32:
                    problem(f"{name} has no Fletcher-32 checksum")
                elif d.size:
                    d[...]
            for slot in ("/restart/slot0", "/restart/slot1"):
                if slot not in f:
                    continue
                for name, shape in (("state", (5,)), ("displacement", (nodes, 3)),
                                    ("previous_displacement", (nodes, 3)),
                                    ("contact", (None,)), ("released", (None,))):
                    if get(f"{slot}/{name}", "f8", len(shape)) is not None:
                        expect(f"{slot}/{name}", shape, str(list(shape)))
        status_ds = datasets.get("/results/contact/status")
        if status_ds is not None and status_ds.size and int(status_ds[...].max()) > 3:
            problem("/results/contact/status holds a value above 3")
        pen = datasets.get("/stats/max_penetration")
        if pen is not None and pen.size and float(np.min(pen[...])) < 0.0:
            problem("/stats/max_penetration holds a negative value")
        counts = [datasets.get(f"/stats/contact_{k}") for k in ("active", "stick", "slip")]
        if all(d is not None and d.shape == (steps,) for d in counts):
            active, stick, slip = (d[...] for d in counts)
            if not np.array_equal(active, stick + slip):
                problem("/stats/contact_active is not /stats/contact_stick + /stats/contact_slip")

    return report(problems)


def report(problems):
    if problems:
        for p in problems:
            print(f"MISMATCH: {p}")
        print(f"check_h5: {len(problems)} problem(s)")
        return 1
    print("check_h5: ok")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
