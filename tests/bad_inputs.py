#!/usr/bin/env python3
"""Bad-input tests for the contact3d CLI (issue #6), driven by tests/errors.cmake.

    bad_inputs.py --bin build/contact3d --source . --case NAME   # one case (a ctest each)
    bad_inputs.py --bin build/contact3d --source . --list        # case names
    bad_inputs.py --bin build/contact3d --source . --all         # every case, a table of messages

Each case builds a broken input in a scratch folder (from the committed fixtures in
meshes/fixtures and the stress base scene), runs the CLI and requires: exit code 2, stderr
starting with "error:", and every listed key fact (case-insensitive substrings) in the message.
"""
import argparse
import os
import shutil
import resource
import subprocess
import sys
import tempfile

SCENE = """[mesh]
file = "{mesh}"
[material]
young = {young}
poisson = {poisson}
body_force = {body_force}
[boundary]
clamped = {clamped}
contact = {contact}
[[boundary.traction]]
group = "load_end"
value = {end}
[[boundary.traction]]
group = "load_top"
value = [0.0, 0.0, -3e7]
[friction]
slip_bound = {g}
law = "ramp"
param = {param}
[contact]
cell_size = {cell}
"""

DEFAULTS = dict(young="21.19e10", poisson="0.277", body_force="[0.0, 0.0, 0.0]", clamped='["clamped"]',
                contact='["contact"]', end="[1e7, 0.0, 2e7]", g="2e7", param="6e4", cell='"2h"')


class Ctx:
    def __init__(self, binary, source, work):
        self.bin, self.src, self.work = binary, os.path.abspath(source), work
        self.fix = os.path.join(self.src, "meshes", "fixtures")

    def path(self, name):
        return os.path.join(self.work, name)

    def fixture(self, name):
        with open(os.path.join(self.fix, name), "rb") as f:
            return f.read()

    def write(self, name, data):
        p = self.path(name)
        with open(p, "wb" if isinstance(data, bytes) else "w") as f:
            f.write(data)
        return p

    def scene(self, mesh=None, **kw):
        v = dict(DEFAULTS)
        v.update(kw)
        v["mesh"] = mesh or os.path.join(self.fix, "brick_n2_msh41.msh")
        return self.write("scene.toml", SCENE.format(**v))

    def msh22_lines(self):
        return self.fixture("brick_n2_msh22.msh").decode().split("\n")


def edit_first_tet(lines, fn):
    """Applies fn(list of fields) to the first 4-node tetrahedron line of an MSH 2.2 file;
    returns (lines, element id)."""
    out, done, eid = [], False, None
    for line in lines:
        t = line.split()
        if not done and len(t) >= 9 and t[1] == "4":
            t = fn(t)
            done, eid = True, t[0]
            line = " ".join(t)
        out.append(line)
    return out, eid


# ---------------------------------------------------------------- cases
# Each returns (argv after the binary, [key facts]).
def c_msh_truncated_ascii(c):
    data = c.fixture("brick_n2_msh41.msh")
    p = c.write("trunc.msh", data[: len(data) // 3])
    return ["check", c.scene(p)], ["trunc.msh"]


def c_msh_truncated_ascii_elements(c):
    data = c.fixture("brick_n2_msh22.msh")
    p = c.write("trunc22.msh", data[: int(len(data) * 0.8)])
    return ["check", c.scene(p)], ["trunc22.msh"]


def c_msh_truncated_binary(c):
    data = c.fixture("brick_n2_msh41_bin.msh")
    p = c.write("truncbin.msh", data[: len(data) // 2])
    return ["check", c.scene(p)], ["truncbin.msh"]


def c_msh_truncated_binary_header(c):
    data = c.fixture("brick_n2_msh41_bin.msh")
    i = data.index(b"$Nodes") + 10
    p = c.write("truncbin2.msh", data[:i])
    return ["check", c.scene(p)], ["truncbin2.msh"]


def c_msh_empty(c):
    p = c.write("empty.msh", b"")
    return ["check", c.scene(p)], ["empty.msh"]


def c_msh_not_a_mesh(c):
    p = c.write("garbage.msh", "hello\nthis is not a mesh\n")
    return ["check", c.scene(p)], ["garbage.msh", "$MeshFormat"]


def c_msh_missing_file(c):
    return ["check", c.scene(c.path("nope.msh"))], ["nope.msh"]


def c_msh_version_3(c):
    lines = c.msh22_lines()
    lines[1] = "3.0 0 8"
    p = c.write("v3.msh", "\n".join(lines))
    return ["check", c.scene(p)], ["3.0", "v3.msh"]


def c_msh22_parametric_nodes(c):
    # gmsh -format msh22 -save_parametric: the nodes in $ParametricNodes (refused as "$Elements comes
    # before $Nodes", which the file did not do)
    text = "\n".join(c.msh22_lines()).replace("$Nodes", "$ParametricNodes").replace("$EndNodes", "$EndParametricNodes")
    return ["check", c.scene(c.write("par22.msh", text))], ["$ParametricNodes", "-save_parametric", "msh41"]


def c_msh_nul_in_section_header(c):
    # "$Nodes\0": the NUL, quoted in the message, ended it there ("section $Nodes" and no reason)
    text = "\n".join(c.msh22_lines()).replace("$Nodes\n", "$Nodes\0\n", 1)
    return ["check", c.scene(c.write("nul.msh", text))], ["$Nodes\\0", "is not closed by"]


def c_msh_version_4_0(c):
    lines = c.fixture("brick_n2_msh41.msh").decode().split("\n")
    lines[1] = "4 0 8"
    p = c.write("v40.msh", "\n".join(lines))
    return ["check", c.scene(p)], ["4", "v40.msh"]


def c_msh_bad_coordinate(c):
    lines = c.msh22_lines()
    i = lines.index("$Nodes") + 2
    lines[i] = "1 0 zero 0"
    p = c.write("badnum.msh", "\n".join(lines))
    return ["check", c.scene(p)], ["badnum.msh", "line"]


def c_msh_nan_coordinate(c):
    lines = c.msh22_lines()
    i = lines.index("$Nodes") + 2
    lines[i] = "1 0 nan 0"
    p = c.write("nan.msh", "\n".join(lines))
    return ["check", c.scene(p)], ["nan.msh"]


def c_msh_unknown_node(c):
    lines, eid = edit_first_tet(c.msh22_lines(), lambda t: t[:5] + ["9999"] + t[6:])
    p = c.write("unknown_node.msh", "\n".join(lines))
    return ["check", c.scene(p)], ["9999"]


def c_msh_cubic_tet(c):
    # second order is read by its corners; third order (20-node tetrahedra) is refused
    lines, eid = edit_first_tet(c.msh22_lines(), lambda t: [t[0], "29"] + t[2:] + [str(k % 6 + 1) for k in range(16)])
    p = c.write("tet20.msh", "\n".join(lines))
    return ["check", c.scene(p)], ["29", "20-node tetrahedron"]


def c_msh_hexahedron(c):
    lines, eid = edit_first_tet(c.msh22_lines(), lambda t: [t[0], "5"] + t[2:] + ["1", "2", "3", "4"])
    p = c.write("hex.msh", "\n".join(lines))
    return ["check", c.scene(p)], ["5"]


def c_msh_inverted_tet(c):
    lines, eid = edit_first_tet(c.msh22_lines(), lambda t: t[:-4] + [t[-3], t[-4], t[-2], t[-1]])
    p = c.write("inverted.msh", "\n".join(lines))
    return ["check", c.scene(p)], [eid]


def c_msh_zero_volume_tet(c):
    lines, eid = edit_first_tet(c.msh22_lines(), lambda t: t[:-1] + [t[-2]])
    p = c.write("flat.msh", "\n".join(lines))
    return ["check", c.scene(p)], [eid]


def c_msh_inverted_tet_solve(c):
    lines, eid = edit_first_tet(c.msh22_lines(), lambda t: t[:-4] + [t[-3], t[-4], t[-2], t[-1]])
    p = c.write("inverted.msh", "\n".join(lines))
    return ["solve", c.scene(p), "--out", c.path("out"), "--quiet"], [eid]


def c_group_misspelt(c):
    return ["check", c.scene(clamped='["clampd"]')], ["clampd", "load_top", "contact"]


def c_group_missing_traction(c):
    text = open(c.scene()).read().replace('group = "load_end"', 'group = "loadend"')
    return ["check", c.write("scene.toml", text)], ["loadend", "load_end"]


def c_group_misspelt_solve(c):
    return ["solve", c.scene(contact='["contacts"]'), "--out", c.path("out"), "--quiet"], ["contacts", "contact"]


def c_contact_not_in_plane(c):
    return ["check", c.scene(contact='["load_top"]')], ["load_top", "z = 0", "none of its triangles faces"]


def c_gamma_u_empty(c):
    # nothing clamped, nothing prescribed and no contact face (contact alone may hold a body)
    return ["check", c.scene(clamped="[]", contact="[]")], ["clamped", "contact"]


def mesh_with_empty_group(c, name, file):
    """The brick's MSH 2.2 file with an extra physical surface `name` that holds no triangle."""
    lines = c.msh22_lines()
    i = lines.index("$PhysicalNames")
    lines[i + 1] = str(int(lines[i + 1]) + 1)
    lines.insert(i + 2, f'2 77 "{name}"')
    return c.write(file, "\n".join(lines))


def c_gamma_u_group_empty(c):
    # a named group without any triangle: an MSH 2.2 file with an extra unused physical name
    p = mesh_with_empty_group(c, "nothing", "unused_group.msh")
    return ["check", c.scene(p, clamped='["nothing"]')], ["nothing"]


def c_gamma_u_group_empty_solve(c):
    argv, facts = c_gamma_u_group_empty(c)
    return ["solve", argv[1], "--out", c.path("out"), "--quiet"], facts + ["clamped"]


def c_load_group_empty(c):
    # a pressure on a named surface group without any triangle (a gmsh selection that found no
    # surface): refused, not dropped from the applied loads in silence
    p = mesh_with_empty_group(c, "side", "empty_side.msh")
    text = open(c.scene(p)).read() + '\n[[boundary.pressure]]\ngroup = "side"\nvalue = 1e6\n'
    return ["solve", c.write("scene.toml", text), "--out", c.path("out"), "--quiet"], ["'side'", "no triangles"]


def c_poisson_half(c):
    return ["check", c.scene(poisson="0.5")], ["material.poisson", "0.5"]


def c_poisson_above(c):
    return ["check", c.scene(poisson="0.7")], ["material.poisson"]


def c_young_zero(c):
    return ["check", c.scene(young="0.0")], ["material.young"]


def c_young_negative(c):
    return ["check", c.scene(young="-1e9")], ["material.young"]


def c_slip_bound_negative(c):
    return ["check", c.scene(g="-1.0")], ["slip_bound"]


def c_young_subnormal(c):
    return ["check", c.scene(young="1e-310")], ["material.young", "subnormal"]


def c_nan_young(c):
    return ["check", c.scene(young="nan")], ["material.young", "finite"]


def c_inf_poisson(c):
    return ["check", c.scene(poisson="inf")], ["material.poisson"]


def c_inf_slip_bound(c):
    return ["check", c.scene(g="inf")], ["slip_bound", "finite"]


def c_nan_traction(c):
    return ["check", c.scene(end="[nan, 0.0, 0.0]")], ["traction", "finite"]


def c_nan_body_force(c):
    return ["check", c.scene(body_force="[0.0, -inf, 0.0]")], ["body_force", "finite"]


def c_nan_param(c):
    return ["check", c.scene(param="nan")], ["param"]


def c_overflowing_body_force(c):
    return ["solve", c.scene(body_force="[0.0, 0.0, -1e305]"), "--out", c.path("out"), "--quiet"], ["load", "overflow"]


def c_overflowing_traction(c):
    return ["solve", c.scene(end="[1e200, 0.0, 0.0]"), "--out", c.path("out"), "--quiet"], ["load", "overflow"]


def c_inf_cell_size(c):
    return ["check", c.scene(cell="inf")], ["cell_size"]


def c_cell_size_far_too_small(c):
    # The message gives the numbers as they are (it printed "0.000000 m gives 3000000000000000000.000000").
    return ["check", c.scene(cell="1e-9")], ["contact.cell_size", "1e-09 m", "3e+18 cells", "larger H"]


def c_cell_size_wrong_unit(c):
    # H = 1 mm on a face meshed at 0.5 m: 3 million cells for 18 contact nodes, refused before they are built
    # (building them took minutes before (5.1) refused them)
    return (["solve", c.scene(cell="0.001"), "--out", c.path("out"), "--quiet"],
            ["contact.cell_size 0.001 m", "3e+06 cells", "free contact nodes", "(5.1)"])


def c_msh_one_partition_of_two(c):
    # gmsh -part 2 -part_split writes one file per partition: a piece of the body, not the body.
    return ["check", c.scene(os.path.join(c.fix, "brick_n2_msh41_part2_split_1.msh"))], \
        ["brick_n2_msh41_part2_split_1.msh", "partitioned into 2 parts", "partition(s) 1 only", "-part_split"]


def c_serial_build_under_mpirun(c):
    # `mpirun -np 2 build/contact3d ...` (the serial build, or build-mpi/contact3d overwritten by a
    # build of every target there) would solve twice into one folder: refused before anything runs.
    # Open MPI's variables, and a parent process named mpirun (a script that runs the solver as its
    # child): a script started by mpirun that runs serial solves itself is not refused.
    launcher = c.write("mpirun", '#!/bin/sh\n"$@"\nexit $?\n')
    os.chmod(launcher, 0o755)
    return ((["solve", c.scene(), "--quiet", "--out", c.path("out")],
             ["serial build", "MPI launcher with 2 processes", "make build-mpi"]),
            {"env": {"OMPI_COMM_WORLD_SIZE": "2", "OMPI_COMM_WORLD_RANK": "0"}, "launcher": [launcher]})


def c_nan_table_point(c):
    s = c.scene()
    text = open(s).read().replace('law = "ramp"\nparam = 6e4', 'law = "table"\npoints = [[0.0, 0.3], [nan, 0.2]]')
    return ["check", c.write("scene.toml", text)], ["friction.points"]


def c_nan_set_override(c):
    return ["check", c.scene(), "--set", "friction.slip_bound=nan"], ["slip_bound", "finite"]


def c_inf_mesh_parameter(c):
    s = c.scene()
    text = open(s).read().replace('file = "', 'parameters = { n = inf }\nfile = "')
    return ["check", c.write("scene.toml", text)], ["mesh.parameters", "finite"]


def c_unknown_key(c):
    s = c.scene()
    text = open(s).read().replace("poisson =", "poison = 0.3\npoisson =")
    return ["check", c.write("scene.toml", text)], ["material.poison"]


def c_invalid_toml(c):
    return ["check", c.write("scene.toml", "[material\nyoung = 1\n")], ["TOML", "line"]


def c_missing_scene(c):
    return ["check", c.path("none.toml")], ["none.toml"]


def c_stability_violation(c):
    return ["solve", c.scene(cell='"0.25h"'), "--out", c.path("out"), "--quiet"], ["5.1"]


def c_out_proc(c):
    return ["solve", c.scene(), "--out", "/proc/contact3d_x", "--quiet"], ["/proc/contact3d_x", "cannot be written"]


def c_out_is_file(c):
    f = c.write("a_file", "x")
    return ["solve", c.scene(), "--out", f, "--quiet"], ["a_file", "cannot be written"]


def c_out_under_file(c):
    f = c.write("a_file", "x")
    return ["solve", c.scene(), "--out", os.path.join(f, "sub"), "--quiet"], ["a_file", "cannot be written"]


def c_mesh_n_zero(c):
    return ["mesh", "brick", "--n", "0", "-o", c.path("b.msh")], ["n"]


# ------------------------------------------------ what the mesh means (issue 13)
class Msh22:
    """The MSH 2.2 fixture as editable nodes, elements and names."""

    def __init__(self, c):
        lines = c.msh22_lines()
        self.head = lines[:lines.index("$Nodes")]
        n0 = lines.index("$Nodes") + 2
        self.nodes = [l.split() for l in lines[n0:lines.index("$EndNodes")]]
        e0 = lines.index("$Elements") + 2
        self.elements = [l.split() for l in lines[e0:lines.index("$EndElements")]]

    def add_element(self, kind, phys, nodes):
        eid = str(max(int(e[0]) for e in self.elements) + 1)
        self.elements.append([eid, str(kind), "2", str(phys), "1"] + [str(v) for v in nodes])
        return eid

    def tets(self):
        return [e for e in self.elements if e[1] == "4"]

    def node_at(self, x, y, z):
        return next(n[0] for n in self.nodes if [float(v) for v in n[1:4]] == [x, y, z])

    def text(self):
        out = self.head + ["$Nodes", str(len(self.nodes))] + [" ".join(n) for n in self.nodes] + ["$EndNodes"]
        out += ["$Elements", str(len(self.elements))] + [" ".join(e) for e in self.elements] + ["$EndElements", ""]
        return "\n".join(out)


def c_mesh_duplicate_tet(c):
    m = Msh22(c)
    first = m.tets()[0]
    eid = m.add_element(4, first[3], first[-4:])
    return ["check", c.scene(c.write("duptet.msh", m.text()))], ["same four nodes", first[0], eid]


def c_mesh_duplicate_load_triangle(c):
    m = Msh22(c)
    tri = next(e for e in m.elements if e[1] == "2" and e[3] == "3")  # load_top
    eid = m.add_element(2, 3, tri[-3:])
    return ["solve", c.scene(c.write("duptri.msh", m.text())), "--out", c.path("out"), "--quiet"], \
        ["load_top", tri[0], eid, "twice"]


def c_mesh_duplicate_group_name(c):
    m = Msh22(c)
    m.head = [l.replace('2 5 "free"', '2 5 "load_top"') for l in m.head]
    return ["check", c.scene(c.write("dupname.msh", m.text()))], ["load_top", "two physical groups"]


def c_mesh_initial_penetration(c):
    m = Msh22(c)
    node = m.node_at(1.5, 0.5, 0.0)  # a node of Γc pushed 1 mm below the plane
    for n in m.nodes:
        if n[0] == node:
            n[3] = "-1e-3"
    return ["check", c.scene(c.write("below.msh", m.text()))], ["below the foundation", f"node {node}", "-0.001"]


def interior_face(m):
    """Three nodes of a face that two tetrahedra of the mesh share."""
    count = {}
    for e in m.tets():
        v = e[-4:]
        for skip in range(4):
            f = tuple(sorted(v[:skip] + v[skip + 1:]))
            count[f] = count.get(f, 0) + 1
    return next(f for f, k in count.items() if k == 2)


def c_mesh_contact_interior_face(c):
    m = Msh22(c)
    eid = m.add_element(2, 4, interior_face(m))
    return ["check", c.scene(c.write("interior.msh", m.text()))], ["interior face", eid]


def c_mesh_load_interior_face(c):
    """A face inside the body in a traction group (the cut face of a gmsh BooleanFragments that a
    bounding-box selection picked up): its load would act inside the body."""
    m = Msh22(c)
    eid = m.add_element(2, 3, interior_face(m))  # load_top
    return ["solve", c.scene(c.write("load_interior.msh", m.text())), "--out", c.path("out"), "--quiet"], \
        ["load group 'load_top'", "interior face", eid]


def c_mesh_contact_not_a_face(c):
    m = Msh22(c)
    eid = m.add_element(2, 4, [m.node_at(0, 0, 0), m.node_at(3, 0, 0), m.node_at(3, 1, 0)])
    return ["check", c.scene(c.write("orphan.msh", m.text()))], ["not a face of any tetrahedron", eid]


def c_mesh_tets_overlap(c):
    """A tetrahedron added over a face that two others share (positively oriented, so that only the
    overlap is wrong): the face of three tetrahedra is named."""
    m = Msh22(c)
    xyz = {n[0]: [float(v) for v in n[1:4]] for n in m.nodes}
    face = interior_face(m)
    used = {v for e in m.tets() if set(face) <= set(e[-4:]) for v in e[-4:]}

    def volume(a, b, c_, d):
        u, v, w = ([xyz[p][i] - xyz[a][i] for i in range(3)] for p in (b, c_, d))
        return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
                + u[2] * (v[0] * w[1] - v[1] * w[0]))
    apex = next(n for n in xyz if n not in used and abs(volume(*face, n)) > 1e-9)
    nodes = list(face) + [apex]
    if volume(*nodes) < 0:
        nodes[0], nodes[1] = nodes[1], nodes[0]
    eid = m.add_element(4, 6, nodes)
    return ["check", c.scene(c.write("overlap.msh", m.text()))], ["share the face of nodes", "overlap", eid]


def small_tet_inside(m, keep_corner):
    """A small positively oriented tetrahedron around the centre of the mesh's first tetrahedron, over new
    nodes (keep_corner: its first node the host's first node instead, so it shares a corner and no face)."""
    host = m.tets()[0]
    xyz = {n[0]: [float(v) for v in n[1:4]] for n in m.nodes}
    centre = [sum(xyz[v][i] for v in host[-4:]) / 4 for i in range(3)]
    offsets = [(0, 0, 0), (0.02, 0, 0), (0, 0.02, 0), (0, 0, 0.02)]
    nodes = []
    for k, d in enumerate(offsets):
        if k == 0 and keep_corner:
            nodes.append(host[-4])
            continue
        nid = str(max(int(n[0]) for n in m.nodes) + 1)
        m.nodes.append([nid] + [repr(centre[i] + d[i] - (0.005 if not keep_corner else 0)) for i in range(3)])
        nodes.append(nid)
    return m.add_element(4, host[3], nodes)


def c_mesh_tet_inside_another(c):
    """An element over four new nodes inside the body (no face, edge or node shared): it would be
    assembled as a stiff stray piece, or float; the tetrahedron holding its centre is named."""
    m = Msh22(c)
    eid = small_tet_inside(m, keep_corner=False)
    return ["check", c.scene(c.write("inside.msh", m.text()))], ["centre of tetrahedron " + eid, "overlap"]


def c_mesh_tet_over_a_corner(c):
    """An element sharing one corner with the mesh and reaching into its tetrahedra: one part with the
    body, joined at a node, refused as an overlap by check_mesh_meaning (it solved, assembled over the
    body, until blocks joined at nodes were searched too; before that, the mechanism check refused it)."""
    m = Msh22(c)
    eid = small_tet_inside(m, keep_corner=True)
    return ["solve", c.scene(c.write("corner.msh", m.text())), "--out", c.path("out"), "--quiet"], \
        ["centre of tetrahedron " + eid, "overlap"]


def c_mesh_tet_outside_at_a_corner(c):
    """An element sharing one corner of the brick and lying outside it: no overlap, one part with the
    body, joined at a node, about which it can turn: the solve's mechanism check refuses it."""
    m = Msh22(c)
    used = {v for e in m.tets() for v in e[-4:]}
    xyz = {n[0]: [float(v) for v in n[1:4]] for n in m.nodes if n[0] in used}
    corner = max(xyz, key=lambda v: sum(xyz[v]))
    nodes = [corner]
    for d in [(0.02, 0, 0), (0, 0.02, 0), (0, 0, 0.02)]:
        nid = str(max(int(n[0]) for n in m.nodes) + 1)
        m.nodes.append([nid] + [repr(xyz[corner][i] + d[i]) for i in range(3)])
        nodes.append(nid)
    m.add_element(4, m.tets()[0][3], nodes)
    return ["solve", c.scene(c.write("corner_out.msh", m.text())), "--out", c.path("out"), "--quiet"], \
        ["only at the node", "ball joint"]


def c_mesh_volumes_over_each_other(c):
    """The body's tetrahedra once more over nodes of their own, moved into it (two meshes written into one
    file, or two gmsh volumes meshed over the same place): it solved before, each copy on its own."""
    m = Msh22(c)
    first_new = max(int(n[0]) for n in m.nodes) + 1
    renumber = {}
    for n in list(m.nodes):
        renumber[n[0]] = str(first_new + len(renumber))
        m.nodes.append([renumber[n[0]], repr(float(n[1]) + 0.43), repr(float(n[2]) + 0.27), repr(float(n[3]) + 0.11)])
    for e in m.tets():
        m.add_element(4, e[3], [renumber[v] for v in e[-4:]])
    return ["check", c.scene(c.write("over.msh", m.text()))], ["lies inside tetrahedron", "overlap"]


def c_mesh_clamped_triangle_not_a_face(c):
    """A triangle of the clamped group that no tetrahedron has as a face (its nodes on Γc): it would
    hold those contact nodes in silence."""
    m = Msh22(c)
    eid = m.add_element(2, 1, [m.node_at(0, 0, 0), m.node_at(3, 0, 0), m.node_at(3, 1, 0)])
    return ["check", c.scene(c.write("clamped_orphan.msh", m.text()))], \
        ["group 'clamped'", "not a face of any tetrahedron", eid]


def c_mesh_clamp_on_a_line(c):
    m = Msh22(c)
    m.elements = [e for e in m.elements if not (e[1] == "2" and e[3] == "1")]  # drop the clamped face
    line = [m.node_at(0, 0, 0), m.node_at(0, 0, 0.5), m.node_at(0, 0, 1)]
    m.add_element(2, 1, line)
    return ["check", c.scene(c.write("line.msh", m.text()))], ["one line", "rotate", "clamped"]


def c_mesh_huge_coordinate(c):
    m = Msh22(c)
    m.nodes[-1][1] = "1e120"
    return ["check", c.scene(c.write("huge.msh", m.text()))], ["1e+120", "units"]


def c_mesh_device_file(c):
    return ["check", c.scene(), "--mesh", "/dev/zero"], ["/dev/zero", "not a regular file"]


def c_geo_fifo(c):
    fifo = c.path("pipe.geo")
    os.mkfifo(fifo)
    text = open(c.scene()).read().replace('file = "', 'geo = "' + fifo + '"\n# file = "')
    return ["check", c.write("geo.toml", text)], ["gmsh script", "pipe.geo", "not a regular file"]


def c_scene_is_directory(c):
    return ["check", c.work], ["is a directory"]


def c_law_value_huge(c):
    s = c.scene()
    text = open(s).read().replace('law = "ramp"', 'law = "constant"\nvalue = 1e302')
    return ["solve", c.write("scene.toml", text), "--out", c.path("out"), "--quiet"], ["friction.value", "1e+302"]


def c_cli_no_scene(c):
    return ["solve"], ["scene", "required"]


def c_cli_unknown_option(c):
    return ["solve", c.scene(), "--bogus"], ["--bogus"]


def c_cli_unknown_option_no_scene(c):
    """A mistyped option before the scene is named: not reported as a missing scene."""
    return ["solve", "--bogus"], ["not expected", "--bogus"]


# ------------------------------------------------ a scene's .geo is code (issue 13)
def geo_scene(c, geo_text):
    os.makedirs(c.path("geo"), exist_ok=True)
    c.write(os.path.join("geo", "body.geo"), geo_text)
    with open(os.path.join(c.src, "pipeline", "scenes", "holed.toml")) as f:
        text = f.read().replace("../../geo/holed.geo", "geo/body.geo")
    text = "\n".join(l for l in text.splitlines() if not l.startswith("dir ="))
    return c.write("geo_scene.toml", text)


def c_geo_system_call(c):
    with open(os.path.join(c.src, "geo", "holed.geo")) as f:
        geo = f.read() + '\nSystemCall "touch contact3d_pwned";\n'
    return ["check", geo_scene(c, geo)], ["SystemCall", "trusted"]


def c_geo_include_outside(c):
    c.write("outside.geo", "h = 0.1;\n")
    with open(os.path.join(c.src, "geo", "holed.geo")) as f:
        geo = 'Include "../outside.geo";\n' + f.read()
    return ["check", geo_scene(c, geo)], ["outside.geo", "outside its folder", "trusted"]


def c_traction_entry_located(c):
    # The second of two [[boundary.traction]] entries has two numbers: the message names the scene file
    # and the line of that entry's value (both entries share the key name).
    with open(os.path.join(c.src, "pipeline", "scenes", "paper_brick.toml")) as f:
        text = f.read().replace("../../geo/brick.geo", os.path.join(c.src, "geo", "brick.geo"))
    text = text.replace("value = [0.0, 0.0, -3e7]", "value = [0.0, -3e7]")
    line = next(i for i, l in enumerate(text.splitlines(), 1) if l.startswith("value = [0.0, -3e7]"))
    return ["check", c.write("two_tractions.toml", text)], ["two_tractions.toml", f"(line {line})",
                                                             "boundary.traction.value", "three numbers"]


def c_geo_syntax_error_named_first(c):
    # A syntax error early in a .geo leaves gmsh reporting later lines by the dozen ("Unknown variable"):
    # the message named only the log's tail, which held none of the first error's line.
    with open(os.path.join(c.src, "geo", "holed.geo")) as f:
        lines = f.read().split("\n")
    lines.insert(2, "broken = ;")
    lines += ["Point(%d) = {zz%d, 0, 0, h};" % (900 + k, k) for k in range(60)]
    return ["solve", geo_scene(c, "\n".join(lines)), "--out", c.path("out"), "--quiet"], \
        ["gmsh failed", "its first error", "line 3"]


def c_refusal_does_not_cite_the_plate_warning(c):
    # The thin slab, free and pulled up: refused for the pull-off, which the warning on too few elements
    # through the plate (about accuracy, given before) cannot cause; it was cited as "may be its cause".
    scene = os.path.join(c.src, "pipeline", "scenes", "slab.toml")
    return (["solve", scene, "--out", c.path("out"), "--quiet", "--set", "boundary.clamped=[]", "--set",
             'boundary.traction=[{group="load_patch",value=[0,0,2e7]}]'],
            ["pull it off the foundation", "!which may be its cause"])


def c_mesh_cut_at_the_file_size_limit(c):
    # ulimit -f below the mesh's size: gmsh (SIGXFSZ ignored, as contact3d ignores it) writes the mesh cut
    # short and exits 0; the reading error read "unexpected end of file" with nothing about the limit.
    scene = os.path.join(c.src, "pipeline", "scenes", "slab.toml")
    return (["solve", scene, "--out", c.path("out"), "--quiet", "--set", "mesh.parameters.h=0.035"],
            ["file-size limit", "ulimit -f", "cut short"]), {"file_size_bytes": 300000}


def c_geo_parameter_unread(c):
    # mesh.parameters names a variable the script never reads (hh for h): gmsh's -setnumber sets it
    # without a word and the mesh came out at the script's own h, exit 0.
    with open(os.path.join(c.src, "geo", "holed.geo")) as f:
        scene = geo_scene(c, f.read())
    return ["check", scene, "--set", "mesh.parameters.hh=0.05"], ["mesh.parameters.hh", "never mentions 'hh'"]


def c_mesh_n_without_generator(c):
    # mesh.n is the built-in brick's size; on a scene meshed by its .geo it was accepted and ignored: the
    # README's own `--set mesh.n=32` solved the brick at the script's n = 16, exit 0, summary n = 32.
    scene = os.path.join(c.src, "pipeline", "scenes", "paper_brick.toml")
    return ["check", scene, "--set", "mesh.n=32"], ["mesh.n", "paper_brick", "mesh.parameters.n=32"]


def c_mesh_parameters_with_a_file(c):
    # mesh.parameters go to a mesh script; on a scene whose mesh is a file they were ignored (a new user's
    # `--set mesh.parameters.n=4` solved the file's mesh, exit 0, nothing said).
    return (["solve", c.scene(), "--set", "mesh.parameters.n=4", "--out", c.path("out"), "--quiet"],
            ["mesh.parameters", "mesh script", "a file", "ignored"])


def c_held_by_contact_on_one_cell_over_the_face(c):
    # contact.cell_size far beyond the face (a length in the wrong unit): one cell, whose single force holds
    # no turn. The refusal led with "the loads along it are more than the contact's friction carries" for a
    # washer whose loads were symmetric up to rounding; the one cell is named first now.
    scene = os.path.join(c.src, "pipeline", "scenes", "paper_brick.toml")
    return (["solve", scene, "--quiet", "--out", c.path("out"), "--set", "mesh.generator=paper_brick", "--set", "mesh.n=4",
             "--set", "boundary.clamped=[]", "--set", "friction.model=coulomb", "--set", "friction.slip_bound=0",
             "--set", "contact.cell_size=100"],
            ["error: the contact partition has only 1 cell(s) over the whole contact face (contact.cell_size)"])


def c_held_by_contact_young_in_wrong_unit(c):
    # young = 210 meant in GPa, the brick held by contact alone (Coulomb): refused for a rigid displacement
    # thousands of times its size, which blamed the contact cells; the refusal must carry the warning
    # that names the unit.
    scene = os.path.join(c.src, "pipeline", "scenes", "paper_brick.toml")
    return (["solve", scene, "--quiet", "--out", c.path("out"), "--set", "mesh.parameters.n=4", "--set",
             "boundary.clamped=[]", "--set", "material.young=210.0", "--set", 'friction.model="coulomb"', "--set",
             "friction.slip_bound=0", "--set", 'friction.law="constant"', "--set", "friction.value=0.3"],
            ["rigid displacement", "this input's warnings, which may be its cause",
             "young = 210 Pa is softer than any solid", "GPa", "the loads reach a stress of 3e+07 Pa"])


# ------------------------------------------------ FreeFEM meshes and scripts (issue 15)
def c_medit_truncated(c):
    data = c.fixture("freefem_cube2.mesh")
    p = c.write("cube.mesh", data[: int(len(data) * 0.6)])
    return ["check", c.scene(p)], ["cube.mesh"]


def c_medit_binary_truncated(c):
    data = c.fixture("freefem_cube2.meshb")
    p = c.write("cube.meshb", data[: len(data) // 2])
    return ["check", c.scene(p)], ["cube.meshb"]


def garbage_bytes():
    """Bytes no mesh writer makes: control bytes, bytes that are not UTF-8, no whitespace."""
    return bytes((37 * k * k + 11 * k + 0x1e) % 256 or 1 for k in range(4096)).replace(b" ", b"!").translate(
        bytes(b if b not in b"\t\n\v\f\r" else 1 for b in range(256)))


def c_medit_binary_garbage(c):
    """Random bytes named .meshb: not binary Medit, said so (not read as text, quoting the bytes)."""
    p = c.write("random.meshb", garbage_bytes())
    return ["check", c.scene(p)], ["random.meshb", "not a Medit binary file"]


def c_medit_text_garbage(c):
    """Random bytes named .mesh: read as text, the unknown keyword quoted printable and short."""
    p = c.write("random.mesh", garbage_bytes())
    return ["check", c.scene(p)], ["random.mesh", "unknown keyword '\\x1e", "...'"]


def edp_scene(c, edp_text):
    c.write("body.edp", edp_text)
    with open(os.path.join(c.src, "pipeline", "scenes", "paper_brick_freefem.toml")) as f:
        text = f.read().replace("../../geo/paper_brick.edp", "body.edp").replace("n = 16", "n = 2")
    text = "\n".join(l for l in text.splitlines() if not l.startswith("dir ="))
    return c.write("edp_scene.toml", text)


def c_edp_system_call(c):
    with open(os.path.join(c.src, "geo", "paper_brick.edp")) as f:
        edp = 'exec("touch contact3d_pwned");\n' + f.read()
    return ["check", edp_scene(c, edp)], ["exec", "trusted"]


def c_edp_script_fails(c):
    with open(os.path.join(c.src, "geo", "paper_brick.edp")) as f:
        edp = f.read() + "\nthis is not FreeFEM;\n"
    return ["check", edp_scene(c, edp)], ["body.edp", "FreeFEM"]


# ------------------------------------------------ boundary conditions users write (issue 14)
def c_displacement_missing_group(c):
    text = open(c.scene()).read().replace("[[boundary.traction]]", '[[boundary.displacement]]\ngroup = "symmetry"\ny = 0.0\n\n[[boundary.traction]]', 1)
    return ["check", c.write("scene.toml", text)], ["symmetry", "free", "load_end"]


def c_displacement_rigid_motion_free(c):
    # u_z = 0 on the bottom face and no contact face: the slides and the turn about z are free
    text = open(c.scene(clamped="[]", contact="[]")).read().replace(
        "[[boundary.traction]]", '[[boundary.displacement]]\ngroup = "contact"\nz = 0.0\n\n[[boundary.traction]]', 1)
    return ["solve", c.write("scene.toml", text), "--out", c.path("out"), "--quiet"], ["free to move", "translation"]


def c_contact_normal_prescribed(c):
    # u_z = 0 prescribed on Γc itself: no cell has a free normal displacement for the contact to act on
    text = open(c.scene()).read().replace(
        "[[boundary.traction]]", '[[boundary.displacement]]\ngroup = "contact"\nz = 0.0\n\n[[boundary.traction]]', 1)
    return (["solve", c.write("scene.toml", text), "--out", c.path("out"), "--quiet"],
            ["no contact node whose normal displacement is free", "cell"])


def c_held_by_friction_too_weak(c):
    # Nothing prescribed: friction alone must hold the body against the end face's 1e7 Pa along x, but
    # g = 2e6 Pa with F <= 0.3 carries at most 0.6e6 Pa over Γc.
    return (["solve", c.scene(clamped="[]", g="2e6"), "--out", c.path("out"), "--quiet"],
            ["friction alone must hold it", "translation along (1, 0, 0)"])


def c_held_by_contact_pulled_off(c):
    # Rollers on x = 0 hold u_x, u_y: the lift is the contact's to hold, and an upward body force
    # pulls the body off the foundation.
    text = open(c.scene(clamped="[]", body_force="[0.0, 0.0, 1e9]")).read().replace(
        "[[boundary.traction]]", '[[boundary.displacement]]\ngroup = "clamped"\nx = 0.0\ny = 0.0\n\n[[boundary.traction]]', 1)
    return (["solve", c.write("scene.toml", text), "--out", c.path("out"), "--quiet"],
            ["held by contact alone", "nothing prescribed holds its lift", "pull it off the foundation",
             "points away from the plane"])


def c_check_pulled_off(c):
    # The same through `check`, which said ok where the solve refuses: the loads' resultant along the
    # normal is checked before anything is factorized.
    args, facts = c_held_by_contact_pulled_off(c)
    return ["check", args[1]], facts


def c_check_pulled_off_beside_a_prescribed_shear(c):
    # A free brick sheared by u_x = 1 mm on one end and pulled up by a body force of 1e-3 N/m³ (3e-3 N in
    # all): the prescribed value's loads, large node by node but nothing along the free lift, made the
    # pull look like rounding to `check` (ok up to about 160 N), which the solve refused after its QP.
    text = ('[mesh]\nfile = "' + os.path.join(c.fix, "brick_n2_msh41.msh") + '"\n[material]\nyoung = 2.1e11\n'
            'poisson = 0.3\nbody_force = [0.0, 0.0, 1e-3]\n[boundary]\nclamped = []\ncontact = ["contact"]\n'
            '[[boundary.displacement]]\ngroup = "clamped"\nx = 1e-3\n'
            '[friction]\nmodel = "coulomb"\nlaw = "constant"\nvalue = 0.3\n')
    return (["check", c.write("sheared.toml", text)],
            ["held by contact alone", "pull it off the foundation", "points away from the plane"])


def c_two_parts_one_floating_pulled_up(c):
    # The floating part of two_parts_one_floating pulled up (a negative pressure on the tops): the cause
    # to name is still that nothing on the contact face holds it, not the pull.
    scene = two_blocks_scene(c, "two_pulled", APART_BOXES, APART_TOP + 'Physical Surface("contact") = Surface In '
                             'BoundingBox {-eps, -eps, -eps, 1 + eps, 1, eps};\nPhysical Volume("body") = {1, 2};\n')
    with open(scene) as f:
        text = f.read().replace("value = 1e6", "value = -1e6")
    return (["check", c.write("two_pulled.toml", text)],
            ["part 2 of 2", "no free node on the contact face", "boundary.contact"])


def c_held_by_contact_frictionless_pushed_sideways(c):
    # A half-cylinder (geo/roller.geo, h = 0.05) on its curved side, its ends held along the axis
    # only, frictionless, pressed on its flat top and pushed across its axis (a traction with a y
    # part): nothing holds the lateral slide, and its loads do not balance.
    text = ('[mesh]\ngeo = "' + os.path.join(c.src, "geo", "roller.geo") + '"\nparameters = { h = 0.05 }\n'
            '[material]\nyoung = 7e10\npoisson = 0.33\n[boundary]\nclamped = []\ncontact = ["contact"]\n'
            '[[boundary.displacement]]\ngroup = "ends"\nx = 0.0\n'
            '[[boundary.traction]]\ngroup = "top"\nvalue = [0.0, 1e6, -2e7]\n'
            '[friction]\nlaw = "none"\n')
    return (["solve", c.write("roller.toml", text), "--out", c.path("out"), "--quiet"],
            ["held by contact alone", "in the foundation's plane", "the contact is frictionless",
             "do not balance", "boundary.displacement", "friction.law"])


def c_held_by_contact_coulomb_zero_pushed_sideways(c):
    # The same roller under Coulomb's model with a coefficient of 0: the message names friction.value (it
    # told a helper to add friction.slip_bound, which Coulomb's model does not read).
    args, facts = c_held_by_contact_frictionless_pushed_sideways(c)
    args = args + ["--set", 'friction.model="coulomb"', "--set", 'friction.law="constant"', "--set",
                   "friction.value=0"]
    return args, facts[:-1] + ["give friction.value a coefficient above 0"]


def c_check_frictionless_pushed_sideways(c):
    # The same half-cylinder through `check`, which said ok where the solve refuses (a helper's free block
    # pushed sideways, frictionless): the balance along the free in-plane motions is checked there too.
    args, facts = c_held_by_contact_frictionless_pushed_sideways(c)
    return ["check", args[1]], facts


def two_blocks_scene(c, name, boxes, groups, contact=True):
    # Two steel blocks meshed by gmsh from `boxes` (its OpenCASCADE lines) with `groups` (its physical
    # groups), the first clamped at x = 0, a pressure of 1 MPa on "top", Coulomb 0.3 where there is
    # contact: the scene file's path.
    geo = ('SetFactory("OpenCASCADE");\n' + boxes + 'Mesh.MeshSizeMin = 0.1; Mesh.MeshSizeMax = 0.1; eps = 1e-6;\n'
           'Physical Surface("clamped") = Surface In BoundingBox {-eps, -eps, -eps, eps, 1, 1};\n' + groups)
    text = ('[mesh]\ngeo = "' + c.write(name + ".geo", geo) + '"\n[material]\nyoung = 2.1e11\npoisson = 0.3\n'
            '[boundary]\nclamped = ["clamped"]\ncontact = ' + ('["contact"]' if contact else '[]') + '\n'
            '[[boundary.pressure]]\ngroup = "top"\nvalue = 1e6\n' +
            ('[friction]\nmodel = "coulomb"\nlaw = "constant"\nvalue = 0.3\n' if contact else ''))
    return c.write(name + ".toml", text)


APART_BOXES = 'Box(1) = {0, 0, 0, 1, 0.5, 0.3};\nBox(2) = {1.5, 0, 0, 1, 0.5, 0.3};\n'
APART_TOP = 'Physical Surface("top") = Surface In BoundingBox {-eps, -eps, 0.3 - eps, 3, 1, 0.3 + eps};\n'


def c_two_parts_one_floating(c):
    # Two blocks in one mesh, sharing no node: the first clamped, the second under a pressure with
    # nothing prescribed on it and its bottom not in the contact group. The contact holds each part
    # that rests on it (its own rigid motions among the dual's equalities), but nothing touches the
    # second: K would be singular along its motions (the factorization once blamed Γu).
    scene = two_blocks_scene(c, "two", APART_BOXES, APART_TOP + 'Physical Surface("contact") = Surface In '
                             'BoundingBox {-eps, -eps, -eps, 1 + eps, 1, eps};\nPhysical Volume("body") = {1, 2};\n')
    return (["solve", scene, "--out", c.path("out"), "--quiet"],
            ["part 2 of 2", "no free node on the contact face", "boundary.contact", "BooleanFragments"])


def c_overlapping_volumes(c):
    # Two boxes overlapping over x in [0.65, 1], meshed without BooleanFragments: two meshes in one space,
    # sharing no node. Solved in silence before, with each cell over the overlap counted twice.
    boxes = 'Box(1) = {0, 0, 0, 1, 0.5, 0.3};\nBox(2) = {0.65, 0.05, 0, 1, 0.5, 0.3};\n'
    scene = two_blocks_scene(c, "overlap", boxes, APART_TOP + 'Physical Surface("contact") = Surface In '
                             'BoundingBox {-eps, -eps, -eps, 3, 1, eps};\nPhysical Volume("body") = {1, 2};\n')
    return (["check", scene], ["lies inside tetrahedron", "two volumes meshed over the same place"])


def c_contact_faces_one_above_another(c):
    # A second block 5 cm above the first and over half of it, both bottoms in the contact group: Γc is
    # no graph over the plane (the overlap check of the volumes passes: they do not overlap).
    boxes = 'Box(1) = {0, 0, 0, 1, 0.5, 0.3};\nBox(2) = {0.5, 0, 0.35, 1, 0.5, 0.3};\n'
    scene = two_blocks_scene(c, "above", boxes, APART_TOP + 'Physical Surface("contact") = Surface In '
                             'BoundingBox {-eps, -eps, -eps, 3, 1, eps};\nPhysical Surface("contact") += Surface In '
                             'BoundingBox {-eps, -eps, 0.35 - eps, 3, 1, 0.35 + eps};\nPhysical Volume("body") = {1, 2};\n')
    return (["check", scene], ["contact face overlaps itself", "graph over the plane"])


def c_two_parts_one_floating_no_contact(c):
    # The same two blocks with no contact face at all: the second block's motions are free and
    # nothing in the scene could hold them.
    scene = two_blocks_scene(c, "two", APART_BOXES, APART_TOP + 'Physical Volume("body") = {1, 2};\n', contact=False)
    return (["solve", scene, "--out", c.path("out"), "--quiet"],
            ["2 disconnected parts", "part 2 of 2", "all six rigid motions are free", "no contact face"])


def c_mesh_hinged_block(c):
    # Two blocks fragmented by gmsh that touch only along an edge (the second sits on the first's far
    # top edge): their meshes share that edge's nodes but no face, so the second turns about the edge
    # with no strain. The solve once "converged" with an equilibrium residual 16 times the forces.
    boxes = ('Box(1) = {0, 0, 0, 1, 0.5, 0.3};\nBox(2) = {1, 0, 0.3, 1, 0.5, 0.3};\n'
             'v() = BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; };\n')
    groups = ('Physical Surface("contact") = Surface In BoundingBox {-eps, -eps, -eps, 3, 1, eps};\n'
              'Physical Surface("top") = Surface In BoundingBox {1 - eps, -eps, 0.6 - eps, 3, 1, 0.6 + eps};\n'
              'Physical Volume("body") = {v()};\n')
    return (["solve", two_blocks_scene(c, "hinge", boxes, groups), "--out", c.path("out"), "--quiet"],
            ["only along the line from (1, 0, 0.3) to (1, 0.5, 0.3)", "a hinge", "singular", "through a face"])


SPHERE_GEO = """SetFactory("OpenCASCADE");
h = 0.04; R = 0.5; eps = 1e-6;
Sphere(1) = {0, 0, R, R};
Box(2) = {-1, -1, -1, 2, 2, 1.3};
v() = BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; };
Recursive Delete { Volume{v(#v() - 1)}; }
Mesh.MeshSizeMin = h; Mesh.MeshSizeMax = h;
low() = Surface In BoundingBox {-R - eps, -R - eps, -eps, R + eps, R + eps, 0.3 + eps};
cut() = Surface In BoundingBox {-R - eps, -R - eps, 0.3 - eps, R + eps, R + eps, 0.3 + eps};
low() -= {cut()};
Physical Surface("contact") = {low()};
rest() = Surface{:};
rest() -= {low(), cut()};
Physical Surface("upper") = {rest()};
Physical Volume("body") = {Volume{:}};
"""


def c_held_by_contact_on_one_cell(c):
    # A steel ball resting on the plane, nothing prescribed, pressed by a pressure on its upper part:
    # its contact zone (Hertz radius of millimetres) lies inside one cell, whose force cannot balance
    # the loads' moments. The refusal must say so (not only "the loads pull the body off").
    c.write("ball.geo", SPHERE_GEO)
    text = ('[mesh]\ngeo = "ball.geo"\n[material]\nyoung = 2.1e11\npoisson = 0.3\n'
            'body_force = [0.0, 0.0, -7.7e4]\n[boundary]\nclamped = []\ncontact = ["contact"]\n'
            '[[boundary.pressure]]\ngroup = "upper"\nvalue = 1e5\n'
            '[friction]\nslip_bound = 1e6\nlaw = "constant"\nvalue = 0.3\n')
    return ["solve", c.write("ball.toml", text), "--out", c.path("out"), "--quiet"], \
        ["held by contact alone", "the body rests on", "cells of the contact partition", "refine the mesh"]


def c_graded_cells_far_too_small(c):
    # Cells of 0.01h on a mesh graded towards the contact point (geo/ball.geo): graded rectangles that
    # small would be tens of millions; refused before they are built (it ran for minutes and then
    # ran out of memory).
    text = open(os.path.join(c.src, "pipeline", "scenes", "ball.toml")).read().replace(
        '"../../geo/ball.geo"', '"' + os.path.join(c.src, "geo", "ball.geo") + '"')
    return ["check", c.write("ball.toml", text), "--set", 'contact.cell_size="0.01h"'], \
        ["contact.cell_size", "0.01h", "graded", "rectangles", "larger multiple of h"]


def c_displacement_conflicting_values(c):
    text = open(c.scene()).read().replace(
        "[[boundary.traction]]", '[[boundary.displacement]]\ngroup = "clamped"\nx = 1e-3\n\n[[boundary.traction]]', 1)
    return ["solve", c.write("scene.toml", text), "--out", c.path("out"), "--quiet"], ["prescribed twice", "clamped"]


def c_displacement_gradient_conflicting(c):
    # u_z = 1e-6 y on the top face, 0 on the clamp: they share the edge x = 0, z = 1 where y > 0
    text = open(c.scene()).read().replace(
        "[[boundary.traction]]", '[[boundary.displacement]]\ngroup = "load_top"\nz = 0.0\n'
        'gradient = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1e-6, 0.0]]\n\n[[boundary.traction]]', 1)
    return ["solve", c.write("scene.toml", text), "--out", c.path("out"), "--quiet"], ["prescribed twice", "load_top"]


def c_displacement_gradient_of_free_component(c):
    text = open(c.scene()).read().replace(
        "[[boundary.traction]]", '[[boundary.displacement]]\ngroup = "load_end"\nx = 0.0\n'
        'gradient = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1e-6, 0.0, 0.0]]\n\n[[boundary.traction]]', 1)
    return ["check", c.write("scene.toml", text)], ["load_end", "gradient row 3", "z is not prescribed"]


def c_pressure_without_value(c):
    text = open(c.scene()).read().replace(
        "[[boundary.traction]]", '[[boundary.pressure]]\ngroup = "free"\n\n[[boundary.traction]]', 1)
    return ["check", c.write("scene.toml", text)], ["boundary.pressure", "free", "value (Pa) and/or a gradient"]


def c_displacement_no_component(c):
    text = open(c.scene()).read().replace(
        "[[boundary.traction]]", '[[boundary.displacement]]\ngroup = "free"\n\n[[boundary.traction]]', 1)
    return ["check", c.write("scene.toml", text)], ["free", "x, y, z"]


def c_pressure_on_volume_group(c):
    text = open(c.scene()).read().replace(
        "[[boundary.traction]]", '[[boundary.pressure]]\ngroup = "body"\nvalue = 1e6\n\n[[boundary.traction]]', 1)
    return ["solve", c.write("scene.toml", text), "--out", c.path("out"), "--quiet"], ["body", "volume"]


def c_material_region_not_volume(c):
    text = open(c.scene()).read().replace(
        "[boundary]", '[[material.region]]\ngroup = "load_top"\nyoung = 7e10\npoisson = 0.3\n\n[boundary]', 1)
    return ["check", c.write("scene.toml", text)], ["load_top", "volume"]


def c_friction_model_unknown(c):
    return ["check", c.scene(), "--set", "friction.model=amontons"], ["friction.model", "'tresca' or 'coulomb'", "amontons"]


def c_coulomb_with_slip_bound(c):
    return ["check", c.scene(), "--set", "friction.model=coulomb"], ["slip_bound", "coulomb", "normal pressure"]


def c_friction_without_law(c):
    # model = "coulomb" and a value but no law: solved frictionless, exit 0, with nothing said (a new user's
    # scene, 2026-12-06); the law is asked for.
    text = open(c.scene()).read().replace('slip_bound = 2e7\nlaw = "ramp"\nparam = 6e4\n',
                                          'model = "coulomb"\nvalue = 0.3\n')
    return ["check", c.write("no_law.toml", text)], ["friction.law is missing", "model, value", "frictionless"]


def c_contact_not_a_graph(c):
    return ["check", c.scene(contact='["free"]')], ["free", "graph over the plane"]


def c_contact_folds_over(c):
    # the bottom faces the foundation, the top away: one group that folds over itself
    return ["check", c.scene(contact='["contact", "load_top"]')], ["load_top", "folds over itself"]


def c_plane_normal_away_from_body(c):
    # the brick rests on z = 0 but the plane's normal points down, away from it
    return (["check", c.scene(), "--set", "contact.plane_normal=[0, 0, -1]"],
            ["'contact'", "none of its triangles faces the foundation", "contact.plane_normal"])


def c_contact_all_clamped(c):
    # every node of the contact group also clamped: nothing can touch the foundation
    return (["solve", c.scene(clamped='["clamped", "contact"]'), "--out", c.path("out")],
            ["every node of the contact groups", "clamped", "no contact node"])


def c_plane_point_far(c):
    # a point of the plane 1e16 along it (a unit slip): the plane is blamed, not the mesh's coordinates
    return (["check", c.scene(), "--set", "contact.plane_point=[1e16, 0, 0]"],
            ["contact.plane_point", "from the mesh", "in the mesh's units"])


def c_plane_normal_zero(c):
    return ["check", c.scene(), "--set", "contact.plane_normal=[0, 0, 0]"], ["contact.plane_normal", "non-zero"]


def c_tilted_plane_penetration(c):
    # The brick n=2 on a foundation tilted about y: its far end lies below the tilted plane, the node
    # named where the user's mesh has it (not in the plane's frame).
    return (["check", c.scene(), "--set", "contact.plane_normal=[-0.3, 0, 1]"],
            ["below the foundation plane", "initial penetration", "at (3, 0, 0) lies 0.862"])


def c_tilted_plane_normal_huge(c):
    # The same plane with its normal's components near overflow (|n|² = inf): its direction counts, so the
    # same refusal, not the untilted plane solved in silence.
    return (["check", c.scene(), "--set", "contact.plane_normal=[-0.3e200, 0, 1e200]"],
            ["below the foundation plane", "initial penetration", "at (3, 0, 0) lies 0.862"])


def c_path_with_nul(c):
    # "brick.msh\u0000x" would open brick.msh: a path ends at a NUL
    return (["check", c.scene(mesh=os.path.join(c.fix, "brick_n2_msh41.msh") + "\\u0000x")],
            ["mesh.file", "NUL"])


def c_qp_rtol_per_err_negative(c):
    return ["check", c.scene(), "--set", "solver.qp_rtol_per_err=-1e-6"], ["solver.qp_rtol_per_err", "[0, 1)"]


def c_fixed_point_tail_err_one(c):
    return ["check", c.scene(), "--set", "solver.fixed_point_tail_err=1"], ["solver.fixed_point_tail_err", "[0, 1)"]


def c_fixed_point_variant_unknown(c):
    return ["check", c.scene(), "--set", "solver.fixed_point=aitkin"], ["solver.fixed_point", "aitken", "aitkin"]


def c_schur_mumps_in_serial_build(c):
    # The serial binary has no distributed backend: asking for it names how to get it.
    return (["solve", c.scene(), "--quiet", "--out", c.path("out"), "--set", "mesh.generator=paper_brick",
             "--set", "mesh.n=2", "--set", "solver.schur=mumps"], ["solver.schur", "mumps", "make build-mpi"])


def c_check_schur_mumps_in_serial_build(c):
    # check refuses it as solve does (it printed ok, and solve refused only after meshing and assembly).
    return (["check", c.scene(), "--set", "solver.schur=mumps"], ["solver.schur", "mumps", "make build-mpi"])


def c_out_of_core_in_serial_build(c):
    # MUMPS's out-of-core mode asked of the serial binary (CHOLMOD keeps its factor in memory).
    return (["solve", c.scene(), "--quiet", "--out", c.path("out"), "--set", "mesh.generator=paper_brick",
             "--set", "mesh.n=2", "--set", f"solver.out_of_core_dir={c.path('.')}"],
            ["solver.out_of_core_dir", "mumps", "make build-mpi"])


def c_out_of_core_dir_missing(c):
    # The directory for MUMPS's factor files must exist and be writable: refused when the scene is read.
    missing = c.path("no_such_dir")
    return ["check", c.scene(), "--set", f"solver.out_of_core_dir={missing}"], ["solver.out_of_core_dir", missing]


def c_memory_factor_too_big(c):
    # The brick n=24 (a 0.63 GiB factor) in a process limited to 700 MB of address space: refused
    # after CHOLMOD's analysis, before the numeric factorization, naming the factor's size.
    return ((["solve", c.scene(), "--quiet", "--out", c.path("out"), "--set", "mesh.generator=paper_brick",
              "--set", "mesh.n=24"], ["not enough memory for the factorization", "nonzeros", "GiB", "coarser mesh"]),
            {"address_space_bytes": 700 * 2**20})


def c_check_memory_factor_too_big(c):
    # The same limit for `check`: its symbolic analysis predicts the factor, and it refuses what the solve
    # would refuse (it said ok, and only the solve, after meshing and assembly, found the factor too big).
    return ((["check", c.scene(), "--set", "mesh.generator=paper_brick", "--set", "mesh.n=24"],
             ["not enough memory for the factorization", "nonzeros", "GiB", "coarser mesh"]),
            {"address_space_bytes": 700 * 2**20})


def c_memory_blas_buffers(c):
    # 300 MB of address space: OpenBLAS could not map its threads' work buffers (128 MiB each) and
    # would retry forever in the factorization (the brick n = 8 hung here): refused at the start.
    return ((["solve", c.scene(), "--quiet", "--out", c.path("out"), "--set", "mesh.generator=paper_brick",
              "--set", "mesh.n=8"], ["address-space limit", "ulimit -v", "OpenBLAS", "MiB", "raise the limit"]),
            {"address_space_bytes": 300 * 2**20})


def c_memory_blas_worker_at_start(c):
    # 100 MB of address space: OpenBLAS's worker thread, started with the library, cannot map its work
    # space and retries forever; the run was refused (exit 2 printed) but never ended, OpenBLAS's
    # finalizer waiting for that thread (a helper's brick). The process now ends without the finalizers.
    return ((["solve", c.scene(), "--quiet", "--out", c.path("out")],
             ["address-space limit", "ulimit -v", "OpenBLAS", "raise the limit"]),
            {"address_space_bytes": 100 * 10**6, "env": {"OPENBLAS_NUM_THREADS": "2"}})


def c_out_empty(c):
    # `--out "$OUTDIR"` with the variable unset: it wrote into results/runs/<scene> without a word
    return ["solve", c.scene(), "--out", ""], ["--out", "empty path", "unset"]


def c_mesh_output_empty(c):
    return ["mesh", "brick", "--n", "2", "-o", ""], ["--output", "empty path"]


CASES = {k[2:]: v for k, v in globals().items() if k.startswith("c_")}


def run(binary, source, name, verbose=True):
    work = tempfile.mkdtemp(prefix="c3d_bad_")
    try:
        spec = CASES[name](Ctx(binary, source, work))
        # A case gives (argv, facts), or ((argv, facts), resource limits of the solver process
        # (address_space_bytes, file_size_bytes), "env": variables added to its environment, "launcher": a
        # command that starts it). A fact "!words" is words the message must not hold.
        (argv, facts), limits = spec if isinstance(spec[0], tuple) else (spec, {})
        def apply_limits():
            if "address_space_bytes" in limits:
                resource.setrlimit(resource.RLIMIT_AS, (limits["address_space_bytes"],) * 2)
            if "file_size_bytes" in limits:
                resource.setrlimit(resource.RLIMIT_FSIZE, (limits["file_size_bytes"],) * 2)
        env = dict(os.environ, **limits.get("env", {}))
        try:
            p = subprocess.run(limits.get("launcher", []) + [binary] + argv, capture_output=True, text=True,
                               timeout=120, preexec_fn=apply_limits, env=env, errors="replace")
        except subprocess.TimeoutExpired:
            if verbose:
                print(f"{name}: FAIL: no exit within 120 s (a hang)")
            return False, "no exit within 120 s"
        err = p.stderr
        problems = []
        if p.returncode != 2:
            problems.append(f"exit code {p.returncode}, expected 2")
        if not err.startswith("error:"):
            problems.append("stderr does not start with 'error:'")
        if any((ch < " " and ch not in "\n\t") or "\x7f" <= ch <= "\x9f" or ch == "\ufffd" for ch in err):
            problems.append("stderr has control characters or is not UTF-8 (bytes quoted from the input must be "
                            "escaped)")
        for fact in facts:  # "!words": words the message must not hold
            if fact.startswith("!") and fact[1:].lower() in err.lower():
                problems.append(f"message holds '{fact[1:]}'")
            elif not fact.startswith("!") and fact.lower() not in err.lower():
                problems.append(f"message lacks '{fact}'")
        msg = err.strip().replace(work + "/", "").replace(work, "<tmp>")
        if verbose:
            print(f"{name}: {'ok' if not problems else 'FAIL: ' + '; '.join(problems)}\n  {msg}")
        return not problems, msg
    finally:
        shutil.rmtree(work, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--case")
    ap.add_argument("--list", action="store_true")
    ap.add_argument("--all", action="store_true")
    ap.add_argument("--markdown", help="with --all: also write a table case | result | message to this file")
    a = ap.parse_args()
    if a.list:
        print("\n".join(CASES))
        return 0
    if a.case:
        ok, _ = run(a.bin, a.source, a.case)
        return 0 if ok else 1
    fails, rows = 0, []
    for name in CASES:
        ok, msg = run(a.bin, a.source, name)
        fails += not ok
        first = (msg.splitlines()[0] if msg else "").replace("|", "/")
        rows.append(f"| {name} | {'ok' if ok else '**FAIL**'} | `{first}` |")
    if a.markdown:
        with open(a.markdown, "w") as f:
            f.write("# Bad inputs (tests/bad_inputs.py, one ctest each via tests/errors.cmake)\n\n"
                    "Each: exit code 2, stderr starting with `error:`, key facts in the message "
                    "(first line shown; scratch paths shortened).\n\n"
                    "| case | result | message |\n|---|---|---|\n" + "\n".join(rows) +
                    f"\n\n**{len(CASES) - fails} / {len(CASES)} ok.**\n")
    print(f"{len(CASES) - fails}/{len(CASES)} bad-input cases ok")
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
