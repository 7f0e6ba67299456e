#!/usr/bin/env python3
"""Reads a .vtu with VTK's own XML reader and prints what the C++ test checks, as JSON.

Usage: vtk_read_vtu.py FILE [FILE_AT_REST]
Prints the point and cell counts, the cell types, every point and cell array's name, component and
tuple counts, the largest displacement norm of the wall nodes (role 0), and with FILE_AT_REST the
largest difference between (points - points at rest) and the displacement array.
Exits 1 when VTK reports an error or reads no points (as VTK 9.1 did with the former ASCII files).
"""
import json
import sys

from vtkmodules.vtkCommonCore import vtkCommand
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
from vtkmodules.util.numpy_support import vtk_to_numpy
import numpy as np


def read(path):
    errors = []
    reader = vtkXMLUnstructuredGridReader()
    reader.AddObserver(vtkCommand.ErrorEvent, lambda obj, ev: errors.append(ev))
    reader.GetExecutive().AddObserver(vtkCommand.ErrorEvent, lambda obj, ev: errors.append(ev))
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    if errors or reader.GetErrorCode() != 0 or grid.GetNumberOfPoints() == 0:
        sys.exit(f"VTK could not read {path}: error code {reader.GetErrorCode()}, {grid.GetNumberOfPoints()} points")
    return grid


def arrays(data):
    return {data.GetArray(i).GetName(): [data.GetArray(i).GetNumberOfComponents(), data.GetArray(i).GetNumberOfTuples()]
            for i in range(data.GetNumberOfArrays())}


grid = read(sys.argv[1])
points = vtk_to_numpy(grid.GetPoints().GetData())
displacement = vtk_to_numpy(grid.GetPointData().GetArray("displacement_mm"))
role = vtk_to_numpy(grid.GetPointData().GetArray("role"))
out = {
    "points": grid.GetNumberOfPoints(),
    "cells": grid.GetNumberOfCells(),
    "cell_types": sorted({grid.GetCellType(i) for i in range(grid.GetNumberOfCells())}),
    "point_arrays": arrays(grid.GetPointData()),
    "cell_arrays": arrays(grid.GetCellData()),
    "max_wall_displacement_mm": float(np.linalg.norm(displacement[role == 0], axis=1).max()),
}
if len(sys.argv) > 2:
    rest = vtk_to_numpy(read(sys.argv[2]).GetPoints().GetData())
    out["max_points_minus_rest_minus_displacement_mm"] = float(np.abs(points - rest - displacement).max())
print(json.dumps(out))
