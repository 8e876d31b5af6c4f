"""The language instruction stored with every recorded episode, from the episode's object."""

from __future__ import annotations

import numpy as np

# A few plain colour names (RGB 0..1): the object's colour is named after the nearest one.
_COLOURS = {"red": (0.9, 0.1, 0.1), "green": (0.1, 0.7, 0.1), "blue": (0.1, 0.2, 0.9), "yellow": (0.9, 0.9, 0.1),
            "orange": (1.0, 0.55, 0.0), "purple": (0.5, 0.1, 0.6), "white": (0.95, 0.95, 0.95),
            "black": (0.05, 0.05, 0.05), "grey": (0.5, 0.5, 0.5)}


def colour_name(rgba) -> str:
    rgb = np.asarray(rgba[:3], float)
    return min(_COLOURS, key=lambda k: float(np.sum((rgb - np.asarray(_COLOURS[k])) ** 2)))


def pick_place_instruction(params) -> str:
    """E.g. "pick the red cube and place it on the target" (``params``: PickPlaceParams)."""
    return f"pick the {_named(params.object)} and place it on the target"


def _named(body) -> str:
    colour = f"{colour_name(body.color)} " if getattr(body, "color", None) else ""
    return f"{colour}{body.name.replace('_', ' ')}"


def grasp_instruction(body) -> str:
    """E.g. "grasp the red cube and lift it" (``body``: the episode's object, a scene Body)."""
    return f"grasp the {_named(body)} and lift it"


def trajectory_instruction(waypoints: int) -> str:
    """E.g. "move the arm through 4 waypoints"."""
    return f"move the arm through {waypoints} waypoints"


def _listed(body) -> str:
    """An object of several by its name, with its colour and shape where the name lacks them:
    "the red box", "the mug"."""
    name = body.name.replace("_", " ")
    colour = colour_name(body.color) if getattr(body, "color", None) else ""
    words = name.split()
    if colour and colour not in words:
        words.insert(0, colour)
    if body.shape != "mesh" and body.shape not in words:
        words.append(body.shape)
    return "the " + " ".join(words)


def pick_place_many_instruction(params, shelf: bool) -> str:
    """E.g. "put the red box, the blue cylinder and the green box into bin_b" or, ``shelf`` (the
    place fixture is a shelf), "... onto level 1 of shelf" (``params``: PickPlaceManyParams;
    objects in the task's order)."""
    names = [_listed(o) for o in params.objects]
    listed = names[0] if len(names) == 1 else f"{', '.join(names[:-1])} and {names[-1]}"
    place = params.place
    where = f"onto level {place.level} of {place.fixture}" if shelf else f"into {place.fixture}"
    return f"put {listed} {where}"


def follow_target_instruction(motion, obstacles: int) -> str:
    """E.g. "follow the target around a circle with the tool, avoiding the obstacle"
    (``motion``: the follow-target Motion; ``obstacles``: how many are in the way)."""
    what = {"static": "reach the target", "circle": "follow the target around a circle",
            "figure8": "follow the target along a figure eight",
            "waypoints": f"follow the target through {len(motion.waypoints)} waypoints"}[motion.type]
    avoid = "" if not obstacles else ", avoiding the obstacle" + ("s" if obstacles > 1 else "")
    return f"{what} with the tool{avoid}"
