"""Pictures of result files at their last step, drawn by ParaView off-screen.

Run by run/render inside ParaView's Python (pvpython, under an X server in memory):

    pvpython render.py RESULT.xmf... [-o DIR] [--scale S] [--size W[xH]] [--view auto|front|iso]

For each RESULT.xmf (the XDMF index the solver writes beside RESULT.h5) it writes
    DIR/<name>.von_mises.png  the deformed mesh coloured by the von Mises stress of each element
    DIR/<name>.plastic_strain.png  (scenes with plastic bodies) the deformed mesh coloured by
                              the equivalent plastic strain of each element
    DIR/<name>.contact.png    the deformed mesh, translucent, with the slave nodes in contact
                              (status stick or slip) as spheres coloured by the magnitude of
                              their contact force (normal and friction parts together),
                              zoomed to them when they occupy a small part of the mesh
    DIR/<name>.render.json    what was drawn: time, step, warp scale factor, value ranges
and prints one line per picture. The mesh is warped by the nodal displacement times a scale
factor (--scale, or chosen so that the largest displacement shows as 5% of the mesh's
bounding-box diagonal, rounded down to 1, 2 or 5 times a power of ten, never below 1); the
factor is written on every picture.

The von Mises stress is computed in ParaView (Python Calculator) from the cell array
`stress`, whose six components are stored in the order xx yy zz xy yz zx:
    sqrt(((xx - yy)^2 + (yy - zz)^2 + (zz - xx)^2) / 2 + 3 (xy^2 + yz^2 + zx^2)).

Exit codes: 0 every picture written, 1 a result could not be drawn (the others still are),
2 bad command line.
"""

import argparse
import json
import math
import os
import sys

import numpy as np
from paraview import servermanager
from paraview.simple import (
    CreateRenderView, Delete, ExtractSelection, GetColorTransferFunction, GetRenderViews,
    GetScalarBar, GetSources, IDSelectionSource, LoadPalette, PythonCalculator, Render,
    SaveScreenshot, Show, Text, WarpByVector, Xdmf3ReaderS)
from vtkmodules.numpy_interface import dataset_adapter as dsa

# The arrays the solver's XDMF writer (src/output/xdmf.rs) gives every step.
POINT_ARRAYS = {"displacement": 3, "reaction": 3, "contact_force": 3, "contact_status": 1,
                "contact_gap": 1}
CELL_ARRAYS = {"stress": 6}

VON_MISES = ("sqrt(0.5 * ((stress[:, 0] - stress[:, 1])**2 + (stress[:, 1] - stress[:, 2])**2"
             " + (stress[:, 2] - stress[:, 0])**2)"
             " + 3.0 * (stress[:, 3]**2 + stress[:, 4]**2 + stress[:, 5]**2))")

# Share of the bounding-box diagonal the largest displacement is drawn as (automatic scale).
SHOWN_DISPLACEMENT = 0.05


class RenderError(Exception):
    pass


def parse_args(argv):
    p = argparse.ArgumentParser(prog="run/render", description=__doc__.split("\n\n")[0])
    p.add_argument("results", nargs="+", metavar="RESULT.xmf")
    p.add_argument("-o", "--output", default="out/render", metavar="DIR",
                   help="directory for the pictures (default out/render)")
    p.add_argument("--scale", type=float, default=None,
                   help="displacement scale factor (default: automatic, stated on the picture)")
    p.add_argument("--size", default="1200", metavar="W[xH]",
                   help="picture width (default 1200) and height in pixels; without a height, "
                        "one fitted to the mesh between 480 and 900")
    p.add_argument("--view", choices=("auto", "front", "iso"), default="auto",
                   help="front: along -z with y up; iso: from (+x, +y, +z); auto: front for a "
                        "mesh thin in z (plane strain), iso otherwise")
    a = p.parse_args(argv)
    try:
        parts = [int(v) for v in a.size.lower().split("x")]
        if len(parts) not in (1, 2) or min(parts) < 100:
            raise ValueError
    except ValueError:
        p.error(f"--size: expected W or WxH in pixels, at least 100, got '{a.size}'")
    a.size = (parts[0], parts[1] if len(parts) == 2 else None)
    if a.scale is not None and not (a.scale > 0 and math.isfinite(a.scale)):
        p.error(f"--scale: expected a positive number, got {a.scale}")
    return a


def nice_floor(x):
    """The largest of 1, 2, 5 times a power of ten that is at most x (x > 0)."""
    e = math.floor(math.log10(x))
    for m in (5, 2, 1):
        if m * 10.0**e <= x * (1 + 1e-12):
            return m * 10.0**e
    return 10.0**e


def fmt(v):
    return f"{v:.4g}"


def times_of(reader):
    tv = reader.TimestepValues
    try:
        return [float(t) for t in tv]
    except TypeError:  # one step: ParaView gives a bare number
        return [float(tv)] if tv is not None else []


def check_arrays(data, path):
    """The arrays the writer promises, with their component counts; an error names the file."""
    for assoc, want, have in (("point", POINT_ARRAYS, data.GetPointData()),
                              ("cell", CELL_ARRAYS, data.GetCellData())):
        for name, comps in want.items():
            a = have.GetArray(name)
            if a is None:
                raise RenderError(f"{path}: no {assoc} array '{name}' at the last step")
            if a.GetNumberOfComponents() != comps:
                raise RenderError(f"{path}: {assoc} array '{name}' has "
                                  f"{a.GetNumberOfComponents()} components, expected {comps}")


def colour_range(lo, hi):
    """A colour-map range: a field uniform to 1e-6 (a patch test) gets +-1% around its value,
    so that round-off is not drawn as the whole colour scale."""
    if hi - lo <= 1e-6 * max(abs(lo), abs(hi)):
        mid = 0.5 * (lo + hi)
        half = 0.01 * abs(mid) if mid != 0 else 1.0
        return mid - half, mid + half, True
    return lo, hi, False


def fitted_view(bounds, direction, up, width, height):
    """Camera (parallel projection along -direction) and picture height for a box:
    the box fills the picture below the title band and left of the colour bar. `height`
    None: chosen from the box's projected shape, between 480 and 900 pixels."""
    lo = np.array(bounds[0::2], float)
    hi = np.array(bounds[1::2], float)
    d = np.array(direction, float)
    d /= np.linalg.norm(d)
    u = np.array(up, float)
    u -= d * (u @ d)
    u /= np.linalg.norm(u)
    r = np.cross(u, d)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                        for z in (lo[2], hi[2])])
    pr, pu = corners @ r, corners @ u
    diag = float(np.linalg.norm(hi - lo)) or 1.0
    half_w = max(0.5 * (pr.max() - pr.min()), 1e-9 * diag)
    half_h = max(0.5 * (pu.max() - pu.min()), 1e-9 * diag)
    # Shares of the picture: the box gets (1 - LEFT - RIGHT) of the width and
    # (1 - TOP - BOTTOM) of the height; the title sits in TOP, the colour bar in RIGHT.
    left, right, top, bottom = 0.03, 0.17, 0.12, 0.04
    if height is None:
        wanted = width * (half_h / (1 - top - bottom)) / (half_w / (1 - left - right))
        height = int(min(900, max(480, round(wanted))))
    aspect = width / height
    scale = max(half_h / (1 - top - bottom), half_w / ((1 - left - right) * aspect))
    centre = r * 0.5 * (pr.min() + pr.max()) + u * 0.5 * (pu.min() + pu.max()) \
        + d * (0.5 * (lo + hi) @ d)
    # Move the focal point so that the box sits in its share of the picture.
    focal = centre + r * ((right - left) * scale * aspect) + u * ((top - bottom) * scale)
    camera = {"CameraParallelProjection": 1, "CameraFocalPoint": list(focal),
              "CameraPosition": list(focal + 2.0 * diag * d), "CameraViewUp": list(u),
              "CameraParallelScale": scale}
    return camera, height


def new_view(width, camera, height):
    view = CreateRenderView()
    view.ViewSize = [width, height]
    view.OrientationAxesVisibility = 1
    for k, v in camera.items():
        setattr(view, k, v)
    return view


def title(view, text):
    t = Text(Text=text)
    d = Show(t, view)
    d.WindowLocation = "Upper Left Corner"
    d.Justification = "Left"
    d.FontSize = 18
    return t


def scalar_bar(view, lut, heading):
    bar = GetScalarBar(lut, view)
    bar.Title = heading
    bar.ComponentTitle = ""
    bar.Visibility = 1
    bar.WindowLocation = "Lower Right Corner"
    bar.TitleFontSize = 18
    bar.LabelFontSize = 16
    bar.ScalarBarLength = 0.5
    bar.RangeLabelFormat = "%-#.4g"
    bar.AutomaticLabelFormat = 1
    return bar


def render_one(xmf, args):
    path = os.path.abspath(xmf)
    if not os.path.isfile(path):
        raise RenderError(f"{xmf}: no such file")
    name = os.path.basename(path)
    name = name[:-len(".xmf")] if name.endswith(".xmf") else os.path.splitext(name)[0]
    # An absolute path: the Xdmf3 readers resolve the HDF5 file beside it (README, XDMF).
    reader = Xdmf3ReaderS(FileName=[path])
    reader.UpdatePipelineInformation()
    times = times_of(reader)
    if not times:
        raise RenderError(f"{xmf}: no time step in the file")
    t = times[-1]
    reader.UpdatePipeline(t)
    data = servermanager.Fetch(reader)
    if data is None or data.GetNumberOfPoints() == 0 or data.GetNumberOfCells() == 0:
        raise RenderError(f"{xmf}: ParaView read no mesh (is {name}.h5 beside it?)")
    check_arrays(data, xmf)
    # Copies: the arrays of a fetched data object share VTK's memory, which the pipeline's
    # next update may reuse.
    mesh = dsa.WrapDataObject(data)
    u = np.array(mesh.PointData["displacement"], dtype=np.float64)
    force = np.array(mesh.PointData["contact_force"], dtype=np.float64)
    status = np.array(mesh.PointData["contact_status"]).reshape(-1)
    bounds = data.GetBounds()
    diag = math.sqrt(sum((bounds[2 * i + 1] - bounds[2 * i]) ** 2 for i in range(3)))
    umax = float(np.sqrt((u * u).sum(axis=1)).max()) if len(u) else 0.0
    if args.scale is not None:
        scale, how = args.scale, "given"
    elif umax > 0 and diag > 0:
        scale, how = max(1.0, nice_floor(SHOWN_DISPLACEMENT * diag / umax)), "automatic"
    else:
        scale, how = 1.0, "automatic"
    in_contact = np.nonzero((status == 1) | (status == 2))[0]
    fmag = np.sqrt((force * force).sum(axis=1))

    vm = PythonCalculator(Input=reader, Expression=VON_MISES, ArrayAssociation="Cell Data",
                          ArrayName="von_mises")
    fm = PythonCalculator(Input=vm, Expression="mag(contact_force)",
                          ArrayAssociation="Point Data", ArrayName="contact_force_magnitude")
    warp = WarpByVector(Input=fm, Vectors=["POINTS", "displacement"], ScaleFactor=scale)
    warp.UpdatePipeline(t)
    warped = servermanager.Fetch(warp)
    vm_values = np.array(dsa.WrapDataObject(warped).CellData["von_mises"]).reshape(-1)
    plastic = data.GetCellData().GetArray("plastic_strain") is not None
    eq = (np.array(dsa.WrapDataObject(warped).CellData["plastic_strain"], dtype=np.float64)
          .reshape(-1) if plastic else None)
    warped_points = np.array(dsa.WrapDataObject(warped).Points, dtype=np.float64)
    wb = warped.GetBounds()

    lx, ly, lz = (wb[1] - wb[0], wb[3] - wb[2], wb[5] - wb[4])
    view_kind = args.view
    if view_kind == "auto":
        view_kind = "front" if lz <= 0.5 * max(lx, ly) else "iso"
    direction, up = ((0, 0, 1), (0, 1, 0)) if view_kind == "front" else ((1.0, 0.8, 1.4), (0, 1, 0))
    width, height = args.size
    step_text = (f"{name}: t = {fmt(t)} (step {len(times)} of {len(times)}), "
                 f"displacement x {fmt(scale)}")
    info = {
        "xmf": xmf, "name": name, "time": t, "step": len(times) - 1, "steps": len(times),
        "points": data.GetNumberOfPoints(), "cells": data.GetNumberOfCells(),
        "warp_scale": scale, "warp_scale_kind": how, "max_displacement": umax,
        "diagonal": diag,
        "view": view_kind, "pictures": {},
    }
    os.makedirs(args.output, exist_ok=True)

    # 1. von Mises stress, per element, the whole mesh.
    camera, h = fitted_view(wb, direction, up, width, height)
    view = new_view(width, camera, h)
    d = Show(warp, view)
    d.Representation = "Surface With Edges"
    d.EdgeColor = [0.2, 0.2, 0.2]
    d.ColorArrayName = ["CELLS", "von_mises"]
    lut = GetColorTransferFunction("von_mises")
    lut.ApplyPreset("Viridis (matplotlib)", True)
    lo, hi, widened = colour_range(float(vm_values.min()), float(vm_values.max()))
    lut.AutomaticRescaleRangeMode = "Never"
    lut.RescaleTransferFunction(lo, hi)
    d.LookupTable = lut
    scalar_bar(view, lut, "von Mises stress")
    title(view, step_text + "\nvon Mises stress of each element (from the cell array stress)"
          + ("\nuniform to 1e-6: colour scale widened to +-1%" if widened else ""))
    view.ViewTime = t
    Render(view)
    png = os.path.join(args.output, f"{name}.von_mises.png")
    SaveScreenshot(png, view, ImageResolution=[width, h])
    info["pictures"]["von_mises"] = {
        "png": png, "size": [width, h], "min": float(vm_values.min()),
        "max": float(vm_values.max()), "colour_range": [lo, hi], "uniform": widened}
    print(f"render: {png}: von Mises stress {fmt(vm_values.min())} .. {fmt(vm_values.max())}"
          f"{' (uniform)' if widened else ''}, displacement x {fmt(scale)} ({how}), t = {fmt(t)}")

    # 1b. Equivalent plastic strain, per element, when the scene has plastic bodies.
    if plastic:
        view = new_view(width, camera, h)
        d = Show(warp, view)
        d.Representation = "Surface With Edges"
        d.EdgeColor = [0.2, 0.2, 0.2]
        d.ColorArrayName = ["CELLS", "plastic_strain"]
        lut = GetColorTransferFunction("plastic_strain")
        lut.ApplyPreset("Inferno (matplotlib)", True)
        lo, hi, widened = colour_range(float(eq.min()), float(eq.max()))
        lut.AutomaticRescaleRangeMode = "Never"
        lut.RescaleTransferFunction(lo, hi)
        d.LookupTable = lut
        scalar_bar(view, lut, "equivalent plastic strain")
        title(view, step_text + "\nequivalent plastic strain of each element (cell array plastic_strain)"
              + ("\nuniform to 1e-6: colour scale widened to +-1%" if widened else ""))
        view.ViewTime = t
        Render(view)
        png = os.path.join(args.output, f"{name}.plastic_strain.png")
        SaveScreenshot(png, view, ImageResolution=[width, h])
        info["pictures"]["plastic_strain"] = {
            "png": png, "size": [width, h], "min": float(eq.min()), "max": float(eq.max()),
            "colour_range": [lo, hi], "yielded_elements": int((eq > 0).sum())}
        print(f"render: {png}: equivalent plastic strain {fmt(eq.min())} .. {fmt(eq.max())},"
              f" {int((eq > 0).sum())} elements yielded, t = {fmt(t)}")

    # 2. Contact: the slave nodes in contact (status stick or slip) as spheres coloured by
    # the magnitude of their contact force, over the translucent mesh; zoomed to them when
    # they occupy a small part of the mesh.
    picture = {"nodes_in_contact": int(len(in_contact))}
    box, zoomed = wb, False
    if len(in_contact):
        xyz = warped_points[in_contact]
        clo, chi = xyz.min(axis=0), xyz.max(axis=0)
        wdiag = math.sqrt(lx * lx + ly * ly + lz * lz)
        cdiag = float(np.linalg.norm(chi - clo))
        if cdiag < 0.4 * wdiag:
            pad = max(0.25 * cdiag, 0.1 * wdiag)
            box = tuple(v for k in range(3) for v in (max(wb[2 * k], clo[k] - pad),
                                                      min(wb[2 * k + 1], chi[k] + pad)))
            zoomed = True
    camera, h = fitted_view(box, direction, up, width, height)
    view2 = new_view(width, camera, h)
    d2 = Show(warp, view2)
    d2.Representation = "Surface With Edges"
    d2.ColorArrayName = ["POINTS", ""]
    d2.DiffuseColor = [0.75, 0.75, 0.78]
    d2.AmbientColor = [0.75, 0.75, 0.78]
    d2.EdgeColor = [0.35, 0.35, 0.4]
    d2.Opacity = 0.35
    if len(in_contact):
        fvals = fmag[in_contact]
        ids = IDSelectionSource(FieldType="POINT",
                                IDs=[v for i in in_contact for v in (0, int(i))])
        nodes = ExtractSelection(Input=warp, Selection=ids)
        dn = Show(nodes, view2)
        dn.Representation = "Points"
        dn.RenderPointsAsSpheres = 1
        dn.PointSize = max(6, min(16, int(600 / math.sqrt(len(in_contact) + 1))))
        dn.ColorArrayName = ["POINTS", "contact_force_magnitude"]
        flut = GetColorTransferFunction("contact_force_magnitude")
        flut.ApplyPreset("Plasma (matplotlib)", True)
        flo, fhi, fwidened = colour_range(float(fvals.min()), float(fvals.max()))
        flut.AutomaticRescaleRangeMode = "Never"
        flut.RescaleTransferFunction(flo, fhi)
        dn.LookupTable = flut
        scalar_bar(view2, flut, "contact force magnitude per node")
        picture.update(min=float(fvals.min()), max=float(fvals.max()), colour_range=[flo, fhi],
                       uniform=fwidened, total=[float(v) for v in force[in_contact].sum(axis=0)])
        what = (f"{len(in_contact)} slave nodes in contact (stick or slip), coloured by the "
                "magnitude of the nodal contact force\n(normal and friction parts together)"
                + ("; zoomed to the contact zone" if zoomed else "")
                + ("\nuniform to 1e-6: colour scale widened to +-1%" if fwidened else ""))
    else:
        what = "no slave node in contact at this step"
    title(view2, step_text + "\n" + what)
    view2.ViewTime = t
    Render(view2)
    png = os.path.join(args.output, f"{name}.contact.png")
    SaveScreenshot(png, view2, ImageResolution=[width, h])
    picture.update(png=png, size=[width, h], zoomed=zoomed)
    info["pictures"]["contact"] = picture
    if len(in_contact):
        print(f"render: {png}: {len(in_contact)} nodes in contact, contact force magnitude "
              f"{fmt(picture['min'])} .. {fmt(picture['max'])}"
              + (", zoomed to the contact zone" if zoomed else ""))
    else:
        print(f"render: {png}: no node in contact at t = {fmt(t)}")

    with open(os.path.join(args.output, f"{name}.render.json"), "w") as f:
        json.dump(info, f, indent=1)
        f.write("\n")


def clear():
    """Deletes every view, then every pipeline object. Views must go before the process
    ends: exiting with live render views makes Debian's ParaView 5.11 fail in GLX
    (GLXBadContext) and exit non-zero after every picture was written."""
    for v in list(GetRenderViews()):
        Delete(v)
    while GetSources():
        # Consumers first: a source can be deleted once nothing reads from it.
        for key, s in list(GetSources().items()):
            if not any(getattr(o, "Input", None) is s for o in GetSources().values()):
                Delete(s)


def main(argv):
    args = parse_args(argv)
    LoadPalette("WhiteBackground")
    failed = 0
    for xmf in args.results:
        try:
            render_one(xmf, args)
        except RenderError as e:
            print(f"render: error: {e}", file=sys.stderr)
            failed += 1
        finally:
            clear()
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
