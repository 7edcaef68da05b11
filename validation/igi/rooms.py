"""The two RADIANCE rooms of the IGI references (issue 24). Each face is one
material: `kind` is the RADIANCE primitive; colours and specularities are
RADIANCE's real arguments. `pattern` puts a two-colour checker
(`colorfunc`) on the face: the material colour is multiplied by `a` on
squares where floor(p/size) + floor(q/size) is even and by `b` elsewhere,
(p, q) the face's two in-plane world coordinates."""

import math

STUDIO = {
    "name": "studio",
    "size": (4.0, 3.0, 2.6),
    "faces": {
        "floor": {
            "kind": "plastic2",
            "color": (0.42, 0.30, 0.20),
            "spec": 0.05,
            "rough_u": 0.18,
            "rough_v": 0.07,
            "u": (math.cos(math.radians(30)), math.sin(math.radians(30)), 0.0),
        },
        "ceiling": {"kind": "plastic", "color": (0.80, 0.80, 0.78), "spec": 0.0, "rough": 0.0},
        "wall_south": {"kind": "plastic", "color": (0.55, 0.55, 0.55), "spec": 0.03, "rough": 0.12},
        "wall_north": {"kind": "plastic", "color": (0.25, 0.45, 0.60), "spec": 0.06, "rough": 0.08},
        "wall_west": {"kind": "metal", "color": (0.80, 0.62, 0.40), "spec": 0.70, "rough": 0.10},
        "wall_east": {
            "kind": "plastic",
            "color": (0.70, 0.70, 0.70),
            "spec": 0.02,
            "rough": 0.15,
            "pattern": {"axes": ("y", "z"), "size": 0.5, "a": (1.0, 1.0, 1.0), "b": (0.55, 0.45, 0.35)},
        },
    },
    # RADIANCE `light` spheres: centre, radius, radiance (W m-2 sr-1).
    "lights": [
        {"name": "l1", "position": (1.0, 1.0, 2.3), "radius": 0.015, "intensity": (2.4, 2.0, 1.5)},
        {"name": "l2", "position": (3.0, 2.0, 2.2), "radius": 0.015, "intensity": (1.5, 1.8, 2.2)},
        {"name": "l3", "position": (2.2, 0.8, 1.4), "radius": 0.015, "intensity": (1.0, 1.0, 1.0)},
    ],
}

CORRIDOR = {
    "name": "corridor",
    "size": (2.0, 5.0, 2.2),
    "faces": {
        "floor": {"kind": "plastic", "color": (0.35, 0.35, 0.35), "spec": 0.02, "rough": 0.15},
        "ceiling": {"kind": "plastic", "color": (0.85, 0.85, 0.85), "spec": 0.01, "rough": 0.20},
        "wall_south": {
            "kind": "plastic",
            "color": (0.60, 0.55, 0.50),
            "spec": 0.04,
            "rough": 0.10,
            "pattern": {"axes": ("x", "z"), "size": 0.4, "a": (1.0, 1.0, 1.0), "b": (0.40, 0.55, 0.80)},
        },
        "wall_north": {"kind": "plastic", "color": (0.30, 0.50, 0.30), "spec": 0.08, "rough": 0.06},
        "wall_west": {
            "kind": "plastic2",
            "color": (0.55, 0.25, 0.20),
            "spec": 0.07,
            "rough_u": 0.06,
            "rough_v": 0.16,
            "u": (0.0, 1.0, 1.0),
        },
        "wall_east": {
            "kind": "metal2",
            "color": (0.60, 0.62, 0.70),
            "spec": 0.50,
            "rough_u": 0.14,
            "rough_v": 0.07,
            "u": (0.0, 0.0, 1.0),
        },
    },
    "lights": [
        {"name": "l1", "position": (1.0, 1.0, 2.0), "radius": 0.01, "intensity": (1.6, 1.5, 1.3)},
        {"name": "l2", "position": (1.2, 2.6, 1.9), "radius": 0.01, "intensity": (1.0, 1.2, 1.5)},
        {"name": "l3", "position": (0.7, 4.0, 2.0), "radius": 0.01, "intensity": (1.8, 1.4, 1.0)},
        {"name": "l4", "position": (1.4, 3.6, 1.1), "radius": 0.01, "intensity": (0.6, 0.7, 0.6)},
    ],
}

ROOMS = [STUDIO, CORRIDOR]
