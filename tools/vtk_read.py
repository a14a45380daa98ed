#!/usr/bin/python3
"""Reads VTK XML output of coapt and prints it as JSON (a checking tool, used by tests).

Usage:
  vtk_read.py FILE [--summary] [--step N] [--indent N]

FILE is a collection (.pvd), a parallel piece list (.pvtu) or a single piece (.vtu). Each
data set is read with VTK's own XML readers (vtkXMLPUnstructuredGridReader for .pvtu,
vtkXMLUnstructuredGridReader for .vtu), so what this prints is what ParaView sees.

Output (JSON on standard output):
  {"file": FILE,
   "steps": [{"time": t or null, "file": path of the data set, "part": p,
              "n_points": n, "n_cells": m,
              "points": ARRAY,                 # coordinates, 3 components
              "cells": {"types": [...], "offsets": [...], "connectivity": [...]},
              "point_data": [ARRAY, ...], "cell_data": [ARRAY, ...],
              "field_data": [ARRAY, ...]}, ...]}
  ARRAY = {"name": s, "type": VTK type name (e.g. "double", "long long"),
           "components": k, "tuples": n, "values": [v0, v1, ...]}   # row-major, flat
With --summary, "values" (and "cells") are left out; each ARRAY has instead
"min" and "max" (one per component), "mean" (per component) and "non_finite" (count).
Non-finite values are printed as null. The time of a .pvd step is its "timestep"; of a
lone .pvtu/.vtu, the field data TimeValue if present, else null.

Exits with status 1 (and a message on standard error) if a file is missing or VTK reports
an error while reading it.
"""

import argparse
import json
import math
import os
import sys
import xml.etree.ElementTree as ElementTree

from vtkmodules.vtkCommonCore import vtkLogger, vtkOutputWindow, vtkStringOutputWindow
from vtkmodules.vtkIOXML import vtkXMLPUnstructuredGridReader, vtkXMLUnstructuredGridReader

try:
    from vtkmodules.util.numpy_support import vtk_to_numpy
except ImportError:  # numpy missing: slower pure-Python path
    vtk_to_numpy = None


class ReadError(Exception):
    pass


class VtkMessages:
    """Captures VTK's error and warning messages (also those of the piece readers inside a
    parallel reader, which raise no event on the reader we hold) instead of printing them."""

    def __init__(self):
        self.window = vtkStringOutputWindow()
        vtkOutputWindow.SetInstance(self.window)
        vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
        self.seen = 0

    def take(self):
        """The messages since the last call."""
        text = self.window.GetOutput() or ""
        new, self.seen = text[self.seen:], len(text)
        return new.strip()


MESSAGES = None


def flat_values(array):
    """The values of a vtkDataArray as a flat Python list (row-major)."""
    if vtk_to_numpy is not None:
        return vtk_to_numpy(array).reshape(-1).tolist()
    n = array.GetNumberOfTuples() * array.GetNumberOfComponents()
    return [array.GetValue(i) for i in range(n)]


def clean(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def describe_array(array, summary):
    name = array.GetName()
    components = array.GetNumberOfComponents()
    tuples = array.GetNumberOfTuples()
    out = {
        "name": name,
        "type": array.GetDataTypeAsString(),
        "components": components,
        "tuples": tuples,
    }
    values = flat_values(array)
    if not summary:
        out["values"] = [clean(v) for v in values]
        return out
    lows, highs, means = [], [], []
    non_finite = 0
    for k in range(components):
        column = values[k::components]
        finite = [v for v in column if not (isinstance(v, float) and not math.isfinite(v))]
        non_finite += len(column) - len(finite)
        lows.append(min(finite) if finite else None)
        highs.append(max(finite) if finite else None)
        means.append(math.fsum(finite) / len(finite) if finite else None)
    out.update({"min": lows, "max": highs, "mean": means, "non_finite": non_finite})
    return out


def arrays_of(data, summary):
    return [describe_array(data.GetAbstractArray(i), summary)
            for i in range(data.GetNumberOfArrays())
            if data.GetAbstractArray(i) is not None and data.GetArray(i) is not None]


def read_dataset(path, summary):
    if not os.path.isfile(path):
        raise ReadError(f"{path}: no such file")
    if path.endswith(".pvtu"):
        reader = vtkXMLPUnstructuredGridReader()
    elif path.endswith(".vtu"):
        reader = vtkXMLUnstructuredGridReader()
    else:
        raise ReadError(f"{path}: not a .pvtu or .vtu file")
    MESSAGES.take()
    reader.SetFileName(path)
    reader.Update()
    messages = MESSAGES.take()
    if "ERROR" in messages or reader.GetErrorCode() != 0:
        raise ReadError(f"{path}: VTK could not read it:\n{messages}")
    grid = reader.GetOutput()
    if grid is None:
        raise ReadError(f"{path}: VTK returned no data")

    out = {
        "file": path,
        "n_points": grid.GetNumberOfPoints(),
        "n_cells": grid.GetNumberOfCells(),
    }
    points = grid.GetPoints()
    if points is not None and points.GetData() is not None:
        out["points"] = describe_array(points.GetData(), summary)
        out["points"]["name"] = "Points"
    else:
        out["points"] = {"name": "Points", "type": "double", "components": 3, "tuples": 0,
                         **({"values": []} if not summary else
                            {"min": [None] * 3, "max": [None] * 3, "mean": [None] * 3,
                             "non_finite": 0})}
    if not summary:
        cells = {"types": [], "offsets": [], "connectivity": []}
        if grid.GetNumberOfCells() > 0:
            cells["types"] = flat_values(grid.GetCellTypesArray())
            cell_array = grid.GetCells()
            cells["offsets"] = flat_values(cell_array.GetOffsetsArray())
            cells["connectivity"] = flat_values(cell_array.GetConnectivityArray())
        out["cells"] = cells
    out["point_data"] = arrays_of(grid.GetPointData(), summary)
    out["cell_data"] = arrays_of(grid.GetCellData(), summary)
    out["field_data"] = arrays_of(grid.GetFieldData(), summary)
    return out


def time_value(described):
    for array in described.get("field_data", []):
        if array["name"] == "TimeValue" and array["tuples"] >= 1:
            if "values" in array:
                return array["values"][0]
            return array["min"][0]
    return None


def read_collection(path):
    """[(time, part, file)] of a .pvd, files relative to the current directory."""
    if not os.path.isfile(path):
        raise ReadError(f"{path}: no such file")
    try:
        root = ElementTree.parse(path).getroot()
    except ElementTree.ParseError as error:
        raise ReadError(f"{path}: not valid XML ({error})")
    if root.tag != "VTKFile" or root.get("type") != "Collection":
        raise ReadError(f"{path}: not a VTK collection (VTKFile type=\"Collection\")")
    collection = root.find("Collection")
    if collection is None:
        raise ReadError(f"{path}: no <Collection> element")
    base = os.path.dirname(path)
    out = []
    for dataset in collection.findall("DataSet"):
        file = dataset.get("file")
        if file is None:
            raise ReadError(f"{path}: a <DataSet> without a file attribute")
        time = dataset.get("timestep")
        out.append((float(time) if time is not None else None,
                    int(dataset.get("part", "0") or 0), os.path.join(base, file)))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("file", help=".pvd, .pvtu or .vtu file")
    parser.add_argument("--summary", action="store_true",
                        help="per array min/max/mean/non-finite count instead of the values")
    parser.add_argument("--step", type=int, default=None,
                        help="only this step of a .pvd (0-based; negative counts from the end)")
    parser.add_argument("--indent", type=int, default=None, help="indent the JSON")
    args = parser.parse_args()
    global MESSAGES
    MESSAGES = VtkMessages()

    try:
        if args.file.endswith(".pvd"):
            entries = read_collection(args.file)
            if args.step is not None:
                try:
                    entries = [entries[args.step]]
                except IndexError:
                    raise ReadError(f"{args.file}: no step {args.step} ({len(entries)} steps)")
            steps = []
            for time, part, file in entries:
                described = read_dataset(file, args.summary)
                steps.append({"time": time, "part": part, **described})
        else:
            described = read_dataset(args.file, args.summary)
            steps = [{"time": time_value(described), "part": 0, **described}]
    except ReadError as error:
        print(f"vtk_read.py: {error}", file=sys.stderr)
        return 1

    json.dump({"file": args.file, "steps": steps}, sys.stdout, indent=args.indent,
              allow_nan=False)
    sys.stdout.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
