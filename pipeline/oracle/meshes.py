"""Meshes for the cross-check: gmsh MSH 2.2 and Medit readers (numpy), and making a scene's mesh with gmsh or FreeFEM."""
from __future__ import annotations

import numpy as np

import os
import subprocess
from pathlib import Path

from oracle.errors import SideFailed


def read_msh22(path: Path):
    """ASCII MSH 2.2: node coordinates (by id), 2D and 3D physical names, boundary triangles + tags."""
    with open(path, "r", errors="replace") as fh:
        lines = fh.read().split("\n")
    i = 0
    names: dict[str, int] = {}
    volume_names: dict[str, int] = {}
    node_ids = None
    coords = None
    tris = []
    tri_tags = []
    seen_format = False
    while i < len(lines):
        line = lines[i].strip()
        if line == "$MeshFormat":
            ver, ftype = lines[i + 1].split()[:2]
            if not ver.startswith("2"):
                raise SideFailed(f"{path}: MSH version {ver}, expected 2.2")
            if ftype != "0":
                raise SideFailed(f"{path}: binary MSH, expected ASCII")
            seen_format = True
            i += 2
        elif line == "$PhysicalNames":
            n = int(lines[i + 1])
            for j in range(n):
                parts = lines[i + 2 + j].split(maxsplit=2)
                dim, tag, name = int(parts[0]), int(parts[1]), parts[2].strip().strip('"')
                if dim == 2:
                    names[name] = tag
                elif dim == 3:
                    volume_names[name] = tag
            i += 2 + n
        elif line == "$Nodes":
            n = int(lines[i + 1])
            data = np.array([lines[i + 2 + j].split() for j in range(n)], dtype=float)
            node_ids = data[:, 0].astype(np.int64)
            coords = data[:, 1:4]
            i += 2 + n
        elif line == "$Elements":
            n = int(lines[i + 1])
            for j in range(n):
                parts = lines[i + 2 + j].split()
                if parts[1] == "2":  # 3-node triangle
                    ntags = int(parts[2])
                    tri_tags.append(int(parts[3]) if ntags > 0 else 0)
                    tris.append([int(x) for x in parts[3 + ntags:6 + ntags]])
            i += 2 + n
        else:
            i += 1
    if not seen_format or node_ids is None:
        raise SideFailed(f"{path}: not a MSH 2.2 file (no $MeshFormat/$Nodes)")
    index = {int(nid): k for k, nid in enumerate(node_ids)}
    tri_idx = np.array([[index[t] for t in tri] for tri in tris], dtype=np.int64).reshape(-1, 3)
    return {"names": names, "volume_names": volume_names, "coords": coords, "tris": tri_idx,
            "tri_tags": np.array(tri_tags, dtype=np.int64)}


def read_medit(path: Path):
    """ASCII Medit .mesh (FreeFEM's savemesh): the same dict as read_msh22; groups are the integer labels."""
    tokens = Path(path).read_text(errors="replace").split()
    coords = tris = None
    tri_tags = []
    i = 0
    while i < len(tokens):
        key = tokens[i]
        if key in ("Vertices", "Triangles", "Tetrahedra", "Edges", "Corners", "Ridges", "RequiredVertices"):
            n = int(tokens[i + 1])
            width = {"Vertices": 4, "Triangles": 4, "Tetrahedra": 5, "Edges": 3}.get(key, 1)
            block = np.array(tokens[i + 2:i + 2 + n * width], dtype=float).reshape(n, width)
            if key == "Vertices":
                coords = block[:, :3]
            elif key == "Triangles":
                tris = block[:, :3].astype(np.int64) - 1
                tri_tags = block[:, 3].astype(np.int64)
            i += 2 + n * width
        elif key == "Dimension" or key == "MeshVersionFormatted":
            i += 2
        else:
            i += 1
    if coords is None or tris is None:
        raise SideFailed(f"{path}: not a Medit mesh with Vertices and Triangles")
    return {"names": {}, "volume_names": {}, "coords": coords, "tris": tris, "tri_tags": np.asarray(tri_tags, dtype=np.int64)}


def write_moved_mesh(src: Path, dst: Path, move) -> None:
    """A copy of an ASCII MSH 2.2 or Medit mesh with every vertex x replaced by move(x) (an (n, 3) array
    to an (n, 3) array); tags, elements and groups unchanged."""
    lines = Path(src).read_text(errors="replace").splitlines()
    medit = Path(src).suffix == ".mesh"
    key = "Vertices" if medit else "$Nodes"
    try:
        start = next(k for k, line in enumerate(lines) if line.strip() == key)
    except StopIteration:
        raise SideFailed(f"{src}: no {key} block to move") from None
    count = int(lines[start + 1].split()[0])
    rows = [lines[start + 2 + k].split() for k in range(count)]
    if medit:  # x y z label
        xyz = np.array([[float(v) for v in r[:3]] for r in rows])
        moved = move(xyz)
        for k, r in enumerate(rows):
            lines[start + 2 + k] = f"{moved[k, 0]:.17g} {moved[k, 1]:.17g} {moved[k, 2]:.17g} {r[3]}"
    else:  # tag x y z
        xyz = np.array([[float(v) for v in r[1:4]] for r in rows])
        moved = move(xyz)
        for k, r in enumerate(rows):
            lines[start + 2 + k] = f"{r[0]} {moved[k, 0]:.17g} {moved[k, 1]:.17g} {moved[k, 2]:.17g}"
    Path(dst).write_text("\n".join(lines) + "\n")


def read_mesh(path: Path):
    return read_medit(path) if Path(path).suffix == ".mesh" else read_msh22(path)


def mesh_parameters(m: dict, n, work: Path, script: Path, suffix: str) -> tuple[dict, Path]:
    """The script's parameters (overridden when given: `n` an int overrides the parameter n, a pair
    (name, value) that parameter) and the mesh file they name in `work`."""
    params = dict(m.get("parameters", {}))
    if n is not None:
        key, value = n if isinstance(n, tuple) else ("n", n)
        params[key] = value
    tag = "-".join(f"{k}{v}" for k, v in sorted(params.items())) or "default"
    return params, work / f"{script.stem}-{tag}{suffix}"


def medit_ascii_copy(src: Path, work: Path) -> Path:
    """An ASCII .mesh of the binary Medit mesh `src`, written by FreeFEM (labels kept), in `work`."""
    out = work / (src.stem + ".mesh")
    edp = work / "meshb_to_mesh.edp"
    edp.write_text(f'load "msh3"\nmesh3 Th = readmesh3("{src}");\nsavemesh(Th, "{out}");\n')
    r = subprocess.run(["FreeFem++", "-nw", str(edp)], capture_output=True, text=True,
                       env=dict(os.environ, FF_LOADPATH="/usr/lib/freefem++"))
    if r.returncode != 0 or not out.exists():
        raise SideFailed(f"FreeFEM could not write {src} as an ASCII .mesh:\n{r.stdout[-2000:]}{r.stderr[-2000:]}")
    return out


def make_mesh(scene: dict, scene_path: Path, n, work: Path, gmsh: str, reuse: bool = False) -> tuple[Path, dict]:
    m = scene.get("mesh", {})
    if "geo" in m:
        geo = (scene_path.parent / m["geo"]).resolve()
        if not geo.exists():
            raise SideFailed(f"{scene_path}: [mesh] geo = {m['geo']!r}: {geo} does not exist")
        params, out = mesh_parameters(m, n, work, geo, ".msh")
        if reuse and out.exists():
            return out, params
        cmd = [gmsh, "-3", "-format", "msh22"]
        for k, v in params.items():
            cmd += ["-setnumber", str(k), str(v)]
        cmd += [str(geo), "-o", str(out)]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0 or not out.exists():
            raise SideFailed(f"gmsh failed ({' '.join(cmd)}):\n{r.stdout[-2000:]}{r.stderr[-2000:]}")
        return out, params
    if "edp" in m:  # FreeFEM makes the mesh; both solvers read its .mesh
        edp = (scene_path.parent / m["edp"]).resolve()
        params, out = mesh_parameters(m, n, work, edp, ".mesh")
        if reuse and out.exists():
            return out, params
        cmd = ["FreeFem++", "-nw", str(edp), "-out", str(out)]
        for k, v in params.items():
            cmd += [f"-{k}", str(v)]
        r = subprocess.run(cmd, capture_output=True, text=True, env=dict(os.environ, FF_LOADPATH="/usr/lib/freefem++"))
        if r.returncode != 0 or not out.exists():
            raise SideFailed(f"FreeFEM failed ({' '.join(cmd)}):\n{r.stdout[-2000:]}{r.stderr[-2000:]}")
        return out, params
    if "file" in m:
        if n is not None:
            raise SideFailed("--n needs a scene meshed from a .geo or .edp ([mesh] geo/edp = ...)")
        src = (scene_path.parent / m["file"]).resolve()
        if not src.exists():
            raise SideFailed(f"{scene_path}: [mesh] file = {m['file']!r}: {src} does not exist")
        if src.suffix == ".mesh":  # Medit ASCII (FreeFEM's savemesh): both solvers read it, its labels the groups
            return src, {}
        if src.suffix == ".meshb":  # Medit binary: FreeFEM writes it out as ASCII (gmsh's conversion drops the labels)
            return medit_ascii_copy(src, work), {}
        with open(src, errors="replace") as fh:
            head = fh.read(200)
        if "$MeshFormat\n2.2 0" in head or "$MeshFormat\r\n2.2 0" in head:
            return src, {}
        out = work / (src.stem + "-msh22.msh")
        cmd = [gmsh, str(src), "-save", "-format", "msh22", "-o", str(out)]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0 or not out.exists():
            raise SideFailed(f"gmsh could not convert {src} to MSH 2.2:\n{r.stderr[-2000:]}")
        return out, {}
    raise SideFailed(f"{scene_path}: the cross-check needs [mesh] geo, edp or file (a gmsh or Medit mesh); "
                     "built-in generators have no FreeFEM counterpart")
