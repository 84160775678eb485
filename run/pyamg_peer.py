#!/usr/bin/env python3
"""PyAMG's smoothed aggregation on a model problem the solver exported.

Usage: run/pyamg_peer.py DIR [--json FILE] [--maxiter N]

DIR is what `solver run --export-operator DIR` wrote: the constrained operator A (CSR as
A_indptr.npy, A_indices.npy, A_data.npy), the right-hand side b.npy, the rigid-body modes
B.npy (unknowns x 6), node_id.npy and direction.npy (what each unknown is) and model.json
(the stopping rule and our CG's iterations on the same problem).

Runs pyamg.smoothed_aggregation_solver(A, B=modes) as a preconditioner of CG from x = 0,
stopped at the absolute residual our CG stopped at: |b - A x| <= tolerance * reference
(model.json's reference_end), that is a relative tolerance of tolerance * reference / |b|.
Two set-ups, both with PyAMG's defaults otherwise (symmetric strength, theta 0, standard
aggregation, smoothed prolongator by Jacobi, symmetric Gauss-Seidel pre- and
post-smoothing, improve_candidates by block Gauss-Seidel):
- scalar: A as it is (one row per free direction of a node);
- nodal: A padded to three unknowns per node as a BSR matrix of 3 x 3 blocks (a
  constrained direction becomes a decoupled unknown with the node's mean diagonal, zero
  right-hand side and zero modes), so that aggregation works on nodes, as PyAMG advises
  for elasticity. Its residual norm includes the padded unknowns (zero at the start).
Prints one line per set-up and, with --json, writes the numbers to FILE.
Exit codes: 0 done, 2 bad input (the message names the file).

Run it with the virtual environment run/setup --pyamg makes: .venv-pyamg/bin/python.
"""

import argparse
import inspect
import json
import sys
import time
from pathlib import Path


def fail(msg):
    print(f"pyamg_peer: {msg}", file=sys.stderr)
    sys.exit(2)


try:
    import numpy as np
    import scipy.sparse as sp
    import pyamg
except ImportError as e:
    fail(f"{e}; install PyAMG with run/setup --pyamg and run this with .venv-pyamg/bin/python")


def load_array(d, name, ndim, dtype_kind):
    path = d / name
    if not path.is_file():
        fail(f"{path}: missing (written by solver run --export-operator {d})")
    try:
        a = np.load(path, allow_pickle=False)
    except (ValueError, OSError) as e:
        fail(f"{path}: not a NumPy array file: {e}")
    if a.ndim != ndim or a.dtype.kind != dtype_kind:
        fail(f"{path}: expected a {ndim}-D array of kind '{dtype_kind}', found {a.ndim}-D {a.dtype}")
    return a


def load(d):
    meta_path = d / "model.json"
    if not meta_path.is_file():
        fail(f"{meta_path}: missing (written by solver run --export-operator {d})")
    try:
        meta = json.loads(meta_path.read_text())
    except (ValueError, OSError) as e:
        fail(f"{meta_path}: not JSON: {e}")
    for key in ("tolerance", "reference_end", "unknowns"):
        if not isinstance(meta.get(key), (int, float)):
            fail(f"{meta_path}: key '{key}' missing or not a number")
    indptr = load_array(d, "A_indptr.npy", 1, "i")
    indices = load_array(d, "A_indices.npy", 1, "i")
    data = load_array(d, "A_data.npy", 1, "f")
    b = load_array(d, "b.npy", 1, "f")
    modes = load_array(d, "B.npy", 2, "f")
    node = load_array(d, "node_id.npy", 1, "i")
    m = b.shape[0]
    if m != meta["unknowns"] or indptr.shape[0] != m + 1 or modes.shape != (m, 6) or node.shape[0] != m:
        fail(f"{d}: the arrays disagree on the number of unknowns ({meta['unknowns']} in model.json)")
    if indices.shape[0] != data.shape[0] or indptr[-1] != data.shape[0]:
        fail(f"{d / 'A_indptr.npy'}: does not match A_indices.npy / A_data.npy")
    if m > 0 and (indices.min() < 0 or indices.max() >= m):
        fail(f"{d / 'A_indices.npy'}: a column index outside 0..{m - 1}")
    a = sp.csr_matrix((data, indices, indptr), shape=(m, m))
    return meta, a, b, modes, node


def padded(a, b, modes, node):
    """A, b and the modes on three unknowns per node (BSR 3 x 3)."""
    m = a.shape[0]
    starts = np.flatnonzero(np.r_[True, node[1:] != node[:-1]])
    counts = np.diff(np.r_[starts, m])
    nodes = starts.shape[0]
    slot = np.repeat(3 * np.arange(nodes), counts) + (np.arange(m) - np.repeat(starts, counts))
    diag = a.diagonal()
    mean = np.add.reduceat(diag, starts) / counts
    taken = np.zeros(3 * nodes, dtype=bool)
    taken[slot] = True
    dummy = np.flatnonzero(~taken)
    coo = a.tocoo()
    rows = np.r_[slot[coo.row], dummy]
    cols = np.r_[slot[coo.col], dummy]
    vals = np.r_[coo.data, mean[dummy // 3]]
    ap = sp.csr_matrix((vals, (rows, cols)), shape=(3 * nodes, 3 * nodes)).tobsr(blocksize=(3, 3))
    bp = np.zeros(3 * nodes)
    bp[slot] = b
    mp = np.zeros((3 * nodes, 6))
    mp[slot] = modes
    return ap, bp, mp


def solve_kwargs(ml):
    """PyAMG names the tolerance `tol` before 5.2 and `rtol` after."""
    params = inspect.signature(ml.solve).parameters
    return "rtol" if "rtol" in params else "tol"


def run(name, a, b, modes, rtol, maxiter):
    t0 = time.perf_counter()
    ml = pyamg.smoothed_aggregation_solver(
        a, B=modes, symmetry="symmetric", strength=("symmetric", {"theta": 0.0})
    )
    setup = time.perf_counter() - t0
    res = []
    x0 = np.zeros_like(b)
    t0 = time.perf_counter()
    kw = {solve_kwargs(ml): rtol}
    x = ml.solve(b, x0=x0, accel="cg", maxiter=maxiter, residuals=res, **kw)
    solve = time.perf_counter() - t0
    true_res = float(np.linalg.norm(b - a @ x))
    return {
        "setup": name,
        "unknowns": int(a.shape[0]),
        "iterations": len(res) - 1,
        "converged": bool(true_res <= rtol * np.linalg.norm(b) * (1 + 1e-8)),
        "residual": true_res,
        "setup_time": setup,
        "solve_time": solve,
        "operator_complexity": float(ml.operator_complexity()),
        "grid_complexity": float(ml.grid_complexity()),
        "levels": len(ml.levels),
        "level_unknowns": [int(level.A.shape[0]) for level in ml.levels],
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dir", type=Path)
    ap.add_argument("--json", type=Path)
    ap.add_argument("--maxiter", type=int, default=2000)
    args = ap.parse_args()
    if not args.dir.is_dir():
        fail(f"{args.dir}: not a directory")
    if args.maxiter < 1:
        fail("--maxiter must be at least 1")
    meta, a, b, modes, node = load(args.dir)
    asym = abs(a - a.T).max() / max(abs(a).max(), np.finfo(float).tiny)
    a = ((a + a.T) * 0.5).tocsr()
    bnorm = float(np.linalg.norm(b))
    if bnorm == 0.0:
        fail(f"{args.dir / 'b.npy'}: the right-hand side is zero")
    absolute = meta["tolerance"] * meta["reference_end"]
    rtol = absolute / bnorm
    out = {
        "dir": str(args.dir),
        "pyamg_version": pyamg.__version__,
        "unknowns": int(a.shape[0]),
        "nonzeros": int(a.nnz),
        "asymmetry": float(asym),
        "rhs_norm": bnorm,
        "absolute_tolerance": absolute,
        "relative_tolerance": rtol,
        "ours_cg_iterations": meta.get("cg_iterations"),
        "runs": [],
    }
    print(
        f"{args.dir}: {a.shape[0]} unknowns, {a.nnz} non-zeros (asymmetry {asym:.1e}), "
        f"stop at |r| <= {absolute:.3e} (relative {rtol:.3e}); ours: {meta.get('cg_iterations')} CG iterations"
    )
    for name, (aa, bb, mm) in (("scalar", (a, b, modes)), ("nodal", padded(a, b, modes, node))):
        r = run(name, aa, bb, mm, rtol * bnorm / float(np.linalg.norm(bb)), args.maxiter)
        out["runs"].append(r)
        print(
            f"  pyamg {name}: {r['iterations']} CG iterations{'' if r['converged'] else ' (not converged)'}, "
            f"setup {r['setup_time']:.2f} s, solve {r['solve_time']:.2f} s, "
            f"operator complexity {r['operator_complexity']:.2f}, {r['levels']} levels {r['level_unknowns']}"
        )
    if args.json:
        try:
            args.json.write_text(json.dumps(out, indent=1) + "\n")
        except OSError as e:
            fail(f"cannot write {args.json}: {e}")


if __name__ == "__main__":
    main()
