#!/usr/bin/env python3
"""PNG pictures of a qdem run's VTU output with ParaView (pvpython, headless).

usage: python3 scripts/render.py KIND OUT_DIR PNG [--time T] [--start S] [--frequency F]
                                                  [--scale K] [--size WxH]

KIND
  boxtest     contact force chains (tubes as thick as the normal force, coloured by it, one
              colour and thickness scale for all panels) under the sleeper (grey), seen along x
              (the stones are left out, as in the paper's figure), at
              four phases of the first load cycle after --start (s, default 0.05) of frequency
              --frequency (Hz, default 3): paper 003 Fig. 13; one panel per phase, framed on
              the bodies and force chains of all four (any scene with contacts); a panel
              without force chains is warned of on stderr
  ballast     the displacement magnitude of the bodies (ballast stones, sleeper) at the last time
              (or --time), warped by --scale (default 1)
  cantilever  von Mises stress on the beam deformed --scale times (default 2000) at --time
              (default the last time)
  bbm         a bonded body's crack: broken bonds in black over the intact ones coloured by
              their stress ratio, at the last time (or --time)

OUT_DIR is a run's output directory (its results.pvd and vtu/); PNG the picture to write.
Run it with python3: it starts itself again under pvpython, through `xvfb-run -a` when there
is no display and xvfb-run is installed (Debian's ParaView renders offscreen only with an X
server), else with --force-offscreen-rendering. Before the picture it renders a small test
scene the same way: when pvpython is missing, or cannot render here (Debian's ParaView without
xvfb-run answers --force-offscreen-rendering with a segmentation fault, exit 245), it says so
and exits 77, the status a test reads as "skipped"; a failure after a working test render is a
real one.
"""

import argparse
import os
import shutil
import signal
import subprocess
import sys
import xml.etree.ElementTree as ET

SKIPPED = 77


def launcher(pvpython):
    """The command line that starts pvpython headless: under `xvfb-run -a` when there is no
    display and xvfb-run is installed, else with --force-offscreen-rendering."""
    if os.environ.get("DISPLAY") or not shutil.which("xvfb-run"):
        return [pvpython, "--force-offscreen-rendering"]
    return ["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", pvpython]


def call(args):
    """Runs args; retries twice when xvfb-run handed pvpython a display whose server is not up
    yet (or is still going from the previous run): ParaView then aborts at once with "bad X
    server connection"."""
    for _ in range(3):
        status = subprocess.call(args)
        if args[0] != "xvfb-run" or (status != -signal.SIGABRT and status != 128 + signal.SIGABRT):
            break
    return status


def describe(status):
    """An exit status as words: a signal's name when the process died of one."""
    number = -status if status < 0 else status - 128 if status > 128 else 0
    try:
        return "killed by %s (exit %d)" % (signal.Signals(number).name, status)
    except ValueError:
        return "exit %d" % status


def relaunch():
    """Restarts this script under pvpython, or exits SKIPPED when there is none or when it
    cannot render a test scene here."""
    pvpython = shutil.which("pvpython")
    if os.environ.get("QDEM_RENDER_UNDER_PVPYTHON"):
        raise ImportError("pvpython started, but paraview.simple or vtk does not import")
    os.environ["QDEM_RENDER_UNDER_PVPYTHON"] = "1"
    if pvpython is None:
        print("render.py: pvpython (ParaView) is not installed; nothing rendered", file=sys.stderr)
        sys.exit(SKIPPED)
    start = launcher(pvpython)
    script = os.path.abspath(__file__)
    probe = call(start + [script, "--probe"])
    if probe != 0:
        print(
            "render.py: %s cannot render here (its test render: %s); nothing rendered. "
            "Install xvfb (Debian: apt-get install xvfb) or run with a display."
            % (" ".join(start), describe(probe)),
            file=sys.stderr,
        )
        sys.exit(SKIPPED)
    sys.exit(call(start + [script] + sys.argv[1:]))


def probe_render():
    """The test render: a sphere in a small offscreen view, saved to a temporary PNG."""
    import tempfile

    view = pv.CreateView("RenderView")
    view.ViewSize = [64, 64]
    pv.Show(pv.Sphere(), view)
    with tempfile.TemporaryDirectory() as tmp:
        pv.SaveScreenshot(os.path.join(tmp, "probe.png"), view)


try:
    import paraview.simple as pv
    from vtkmodules.vtkFiltersCore import vtkImageAppend
    from vtkmodules.vtkIOImage import vtkPNGReader, vtkPNGWriter
except ImportError:
    if __name__ == "__main__":
        relaunch()
    raise


def series(out_dir):
    """The times of results.pvd, each with its files by kind (state, spheres, contacts,
    walls, bonds), in time order."""
    root = ET.parse(os.path.join(out_dir, "results.pvd")).getroot()
    times = {}
    for entry in root.iter("DataSet"):
        name = os.path.basename(entry.get("file"))
        kind = name.split("_")[0].split(".")[0]
        path = os.path.join(out_dir, entry.get("file"))
        times.setdefault(float(entry.get("timestep")), {})[kind] = path
    return sorted(times.items())


def at(times, t):
    """The (time, files) of `times` nearest to t (the last one for None)."""
    if t is None:
        return times[-1]
    return min(times, key=lambda item: abs(item[0] - t))


def reader(path):
    return pv.XMLUnstructuredGridReader(FileName=[path])


def view(size):
    v = pv.CreateRenderView()
    v.ViewSize = list(size)
    v.OrientationAxesVisibility = 0
    v.Background = [1.0, 1.0, 1.0]
    try:
        v.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    return v


def colour_by(display, v, association, array, lut_range, title, preset="Viridis (matplotlib)"):
    pv.ColorBy(display, (association, array))
    lut = pv.GetColorTransferFunction(array)
    lut.ApplyPreset(preset, True)
    lut.RescaleTransferFunction(*lut_range)
    lut.AutomaticRescaleRangeMode = "Never"
    display.SetScalarBarVisibility(v, True)
    bar = pv.GetScalarBar(lut, v)
    bar.Title = title
    bar.ComponentTitle = ""
    bar.TitleColor = bar.LabelColor = [0.1, 0.1, 0.1]
    bar.TitleFontSize = bar.LabelFontSize = 12
    return lut


def label(v, text):
    t = pv.Text(Text=text)
    d = pv.Show(t, v)
    d.Color = [0.1, 0.1, 0.1]
    d.FontSize = 13
    d.WindowLocation = "Upper Left Corner"


def camera(v, focal, direction, distance, up=(0.0, 0.0, 1.0), parallel_scale=None):
    v.CameraFocalPoint = list(focal)
    v.CameraPosition = [f - distance * d for f, d in zip(focal, direction)]
    v.CameraViewUp = list(up)
    if parallel_scale is not None:
        v.CameraParallelProjection = 1
        v.CameraParallelScale = parallel_scale


def save(v, png):
    pv.Render(v)
    pv.SaveScreenshot(png, v, ImageResolution=list(v.ViewSize), CompressionLevel="9")


def join(panels, png):
    """The PNG files `panels` side by side in `png` (the panels are removed)."""
    append = vtkImageAppend()
    append.SetAppendAxis(0)
    readers = []
    for p in panels:
        r = vtkPNGReader()
        r.SetFileName(p)
        r.Update()
        readers.append(r)
        append.AddInputConnection(r.GetOutputPort())
    writer = vtkPNGWriter()
    writer.SetCompressionLevel(9)
    writer.SetFileName(png)
    writer.SetInputConnection(append.GetOutputPort())
    writer.Write()
    for p in panels:
        os.remove(p)


def range_of(source, association, array):
    source.UpdatePipeline()
    data = source.CellData if association == "CELLS" else source.PointData
    return data[array].GetRange(-1 if data[array].GetNumberOfComponents() > 1 else 0)


def bounds_of(sources):
    """The box (xmin, xmax, ymin, ymax, zmin, zmax) around the data of `sources`; None when
    they hold nothing."""
    boxes = []
    for s in sources:
        s.UpdatePipeline()
        info = s.GetDataInformation()
        if info.GetNumberOfPoints() > 0:
            boxes.append(info.GetBounds())
    if not boxes:
        return None
    return [f(b[k] for b in boxes) for k in range(6) for f in [(min, max)[k % 2]]]


def warn_empty(kind, t, what):
    """Says on stderr that the panel at time t would show nothing of `what`."""
    print("render.py: warning: %s panel at t = %.4f s: %s" % (kind, t, what), file=sys.stderr)


def boxtest(args):
    times = series(args.out_dir)
    period = 1.0 / args.frequency
    phases = [at(times, args.start + k * period / 4.0) for k in range(4)]
    if any("contacts" not in files for _, files in phases):
        sys.exit("render.py: %s has no contacts VTU (a scene without contact spheres?); "
                 "use the ballast or cantilever kind" % args.out_dir)
    contacts = [reader(files["contacts"]) for _, files in phases]
    for (t, _), c in zip(phases, contacts):
        c.UpdatePipeline()
        if c.GetDataInformation().GetNumberOfCells() == 0:
            warn_empty("boxtest", t, "no touching contacts, so no force chains (is --start "
                       "before the load, or the run shorter than the cycle?)")
    # Frame on the data (the bodies and every phase's force chains), seen along x.
    frame = bounds_of([reader(files["state"]) for _, files in phases] + contacts)
    if frame is None:
        sys.exit("render.py: nothing to draw in %s: no body and no contact" % args.out_dir)
    focal = [(frame[2 * k] + frame[2 * k + 1]) / 2.0 for k in range(3)]
    width, height = frame[3] - frame[2], frame[5] - frame[4]
    half_height = 0.55 * max(height, width * args.size[1] / args.size[0], 1e-9)
    largest = max(range_of(c, "CELLS", "normal_force_magnitude")[1] for c in contacts)
    radius = range_of(reader(phases[0][1]["spheres"]), "POINTS", "radius")[1]
    panels = []
    for k, ((t, files), c) in enumerate(zip(phases, contacts)):
        v = view(args.size)
        sleeper = pv.WarpByVector(Input=reader(files["state"]), Vectors=["POINTS", "displacement"])
        d = pv.Show(sleeper, v)
        pv.ColorBy(d, None)
        d.DiffuseColor = d.AmbientColor = [0.7, 0.7, 0.72]
        points = pv.CellDatatoPointData(Input=pv.ExtractSurface(Input=c))
        thickness = pv.Calculator(Input=points, AttributeType="Point Data")
        thickness.ResultArrayName = "tube_radius"
        thickness.Function = "normal_force_magnitude*%.17g" % (0.3 * radius / max(largest, 1e-300))
        tubes = pv.Tube(Input=thickness)
        tubes.Scalars = ["POINTS", "tube_radius"]
        tubes.VaryRadius = "By Absolute Scalar"
        tubes.NumberofSides = 10
        d = pv.Show(tubes, v)
        colour_by(d, v, "POINTS", "normal_force_magnitude", (0.0, largest), "normal force (N)",
                  "Inferno (matplotlib)")
        d.SetScalarBarVisibility(v, k == 3)
        label(v, "t = %.3f s, %s" % (t, ["load at its minimum", "load rising", "load at its maximum", "load falling"][k]))
        pv.Render(v)
        camera(v, focal, (1.0, 0.0, 0.0), 10.0 * half_height, parallel_scale=half_height)
        panel = "%s.panel%d.png" % (args.png, k)
        save(v, panel)
        panels.append(panel)
    join(panels, args.png)


def bodies(args, array, association, title, direction, scale_default):
    """The state VTU at --time, warped by its displacement, coloured by `array`, framed on
    the data."""
    t, files = at(series(args.out_dir), args.time)
    if bounds_of([reader(files["state"])]) is None:
        warn_empty(args.kind, t, "the state VTU has no body (a scene of [granular] stones only?)")
    scale = scale_default if args.scale is None else args.scale
    v = view(args.size)
    warped = pv.WarpByVector(Input=reader(files["state"]), Vectors=["POINTS", "displacement"])
    warped.ScaleFactor = scale
    d = pv.Show(warped, v)
    if array == "displacement":
        lo, hi = range_of(warped, "POINTS", "displacement")
    else:
        lo, hi = range_of(warped, association, array)
    colour_by(d, v, association, array, (lo, hi), title)
    if array == "displacement":
        pv.GetColorTransferFunction(array).VectorMode = "Magnitude"
    note = "" if scale == 1 else ", displacement x %g" % scale
    label(v, "t = %.3f s%s" % (t, note))
    v.ResetCamera()
    pv.Render(v)
    focal = v.CameraFocalPoint
    distance = sum((p - f) ** 2 for p, f in zip(v.CameraPosition, focal)) ** 0.5
    camera(v, focal, direction, distance * args.zoom)
    save(v, args.png)


def ballast(args):
    bodies(args, "displacement", "POINTS", "displacement (m)", (-0.5, 0.8, -0.45), 1.0)


def cantilever(args):
    bodies(args, "von_mises", "CELLS", "von Mises stress (Pa)", (0.3, 1.0, -0.35), 2000.0)


def bbm(args):
    t, files = at(series(args.out_dir), args.time)
    v = view(args.size)
    bonds = reader(files["bonds"])
    intact = pv.Threshold(Input=bonds, Scalars=["CELLS", "intact"])
    intact.LowerThreshold, intact.UpperThreshold = 0.5, 1.5
    d = pv.Show(intact, v)
    colour_by(d, v, "CELLS", "stress_ratio", (-1.0, 1.0), "stress / strength", "Cool to Warm")
    broken = pv.Threshold(Input=bonds, Scalars=["CELLS", "intact"])
    broken.LowerThreshold, broken.UpperThreshold = -0.5, 0.5
    broken.UpdatePipeline()
    count = broken.GetDataInformation().GetNumberOfCells()
    d = pv.Show(broken, v)
    pv.ColorBy(d, None)
    d.DiffuseColor = d.AmbientColor = [0.0, 0.0, 0.0]
    d.LineWidth = 4.0
    label(v, "t = %.4f s, %d bonds broken" % (t, count))
    v.ResetCamera()
    pv.Render(v)
    focal = list(v.CameraFocalPoint)
    bounds = bonds.GetDataInformation().GetBounds()
    half = 0.6 * max(bounds[1] - bounds[0], (bounds[3] - bounds[2]) * args.size[0] / args.size[1])
    camera(v, focal, (0.0, 0.0, -1.0), 5.0, up=(0.0, 1.0, 0.0),
           parallel_scale=half * args.size[1] / args.size[0])
    save(v, args.png)


def main():
    if sys.argv[1:] == ["--probe"]:
        probe_render()
        return
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("kind", choices=["boxtest", "ballast", "cantilever", "bbm"])
    p.add_argument("out_dir")
    p.add_argument("png")
    p.add_argument("--time", type=float)
    p.add_argument("--start", type=float, default=0.05)
    p.add_argument("--frequency", type=float, default=3.0)
    p.add_argument("--scale", type=float)
    p.add_argument("--size", default=None)
    p.add_argument("--zoom", type=float, default=0.5, help="camera distance over ParaView's reset one (ballast, cantilever)")
    args = p.parse_args()
    default = {"boxtest": "360x380"}.get(args.kind, "900x420")
    args.size = tuple(int(x) for x in (args.size or default).split("x"))
    {"boxtest": boxtest, "ballast": ballast, "cantilever": cantilever, "bbm": bbm}[args.kind](args)
    print("wrote %s" % args.png)


if __name__ == "__main__":
    main()
