"""Independent check of Flurry's VDB files with Debian's OpenVDB tools, not our reader.

usage: check_vdb.py DIR NAME EXPECTED_FILES

Every NAME.NNNN.vdb in DIR is listed by `vdb_print -l` (which reads every grid, the points
too) and its fog grids are opened with pyopenvdb (python3-openvdb; it cannot open point
grids): names, classes, vector types, metadata, and the density integral against the
mass the writer recorded. Exits non-zero with a message on the first problem.
"""
import glob
import math
import os
import re
import subprocess
import sys

import pyopenvdb as vdb


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def main():
    folder, name, expected = sys.argv[1], sys.argv[2], int(sys.argv[3])
    files = sorted(glob.glob(os.path.join(folder, name + ".*.vdb")))
    if len(files) != expected:
        fail(f"{len(files)} files in {folder}, expected {expected}: {files}")
    leftovers = [f for f in os.listdir(folder) if ".tmp." in f]
    if leftovers:
        fail(f"temporary files left behind: {leftovers}")
    for path in files:
        if not re.fullmatch(re.escape(name) + r"\.\d{4}\.vdb", os.path.basename(path)):
            fail(f"unexpected file name {path}")
        out = subprocess.run(["vdb_print", "-l", path], capture_output=True, text=True)
        if out.returncode != 0:
            fail(f"vdb_print {path}: {out.stderr}")
        names = re.findall(r"^Name: (\S+)", out.stdout, re.M)
        if sorted(names) != ["Cd", "density", "points", "vel"]:
            fail(f"{path}: grids {names}")
        if "Tree_ptdataidx32" not in out.stdout:
            fail(f"{path}: 'points' is not a PointDataGrid")

        meta = vdb.readMetadata(path)
        frame = int(os.path.basename(path).split(".")[-2])
        if meta.get("flurry:frame") != frame:
            fail(f"{path}: flurry:frame {meta.get('flurry:frame')}")
        if meta.get("flurry:velocity_units") != "world units per second":
            fail(f"{path}: velocity units {meta.get('flurry:velocity_units')}")

        density = vdb.read(path, "density")
        if density.gridClass != "fog volume":
            fail(f"{path}: density class {density.gridClass}")
        vs = density.transform.voxelSize()
        total = sum(it.value * it.count for it in density.citerOnValues())
        integral = total * vs[0] * vs[1] * vs[2]
        mass = meta["flurry:mass"]
        # Float voxel values summed in double: 1e-5 is far above the rounding (~1e-7) and
        # far below what a lost particle or an unnormalised kernel costs (~1e-3 and more).
        if mass <= 0 or not math.isclose(integral, mass, rel_tol=1e-5):
            fail(f"{path}: density integral {integral} != recorded mass {mass}")
        vel = vdb.read(path, "vel")
        if vel.vectorType != "contravariant relative" or vel.metadata.get("units") != \
                "world units per second":
            fail(f"{path}: vel vector type {vel.vectorType}, units {vel.metadata.get('units')}")
        cd = vdb.read(path, "Cd")
        if cd.activeVoxelCount() != density.activeVoxelCount():
            fail(f"{path}: Cd and density topologies differ")
        print(f"ok {path}: density integral {integral:.6g} = mass {mass:.6g}, "
              f"{density.activeVoxelCount()} voxels")


if __name__ == "__main__":
    main()
