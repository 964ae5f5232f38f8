"""A world and the simulated robot's body as plain JSON for the browser's arena drawing."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from tablebot.sim.model.params import Params
from tablebot.sim.model.world import World


def world_json(world: World, params: Params | None = None) -> dict[str, Any]:
    """Walls, obstacles, lamps, start pose and reach (metres, degrees), plus the robot's outline and sensors."""
    data: dict[str, Any] = {
        "name": world.name,
        "walls": [list(p) for p in world.walls],
        "boxes": [[list(c) for c in box.corners()] for box in world.boxes],
        "circles": [[*c.at, c.radius] for c in world.circles],
        "segments": [[*s.start, *s.end] for s in world.segments],
        "tape": [
            {"points": [list(p) for p in line.points], "width": line.width, "closed": line.closed}
            for line in world.lines
        ],
        "lamps": [{"at": list(lamp.at), "intensity": lamp.intensity, "radius": lamp.radius} for lamp in world.lamps],
        "start": list(world.start),
        "reach": world.reach,
    }
    if params is not None:
        body, light = params["body"], params["light"]
        data["body"] = {
            "front": body["front"],
            "rear": body["rear"],
            "half_width": body["half_width"],
            "overlap": body["bumper_overlap"],
        }
        if params.wiring.get("light_right") or params.wiring.get("light_left"):  # only a robot that has them
            data["light"] = {
                "forward": light["forward"],
                "sideways": light["sideways"],
                "toe_out": light["toe_out"],
                "half_response": light["half_response"],
            }
        data["charge"] = params["battery"]["charge"]
    return data


def moved(
    world: World, start: tuple[float, float, float] | None = None, lamp: tuple[float, float] | None = None
) -> World:
    """The world with its start pose and/or its first lamp moved (the arena's clicks); never saved."""
    if start is not None:
        world = replace(world, start=start)
    if lamp is not None and world.lamps:
        world = replace(world, lamps=(replace(world.lamps[0], at=lamp), *world.lamps[1:]))
    return world
