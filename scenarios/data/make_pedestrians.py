#!/usr/bin/env python3
"""Writes the recorded-style pedestrian tracks of scenarios/pedestrians.toml.

NOT real data: synthetic walks, generated once by this script and committed. Each walker follows
a list of waypoints at a walking speed of 1.0-1.4 m/s, with stops (the walker stands still) and
turns, sampled at 10 Hz like a motion-capture or tracker log, with +-1 cm of seeded jitter on x and
y (none while standing, so that a stop stays a stop). Positions are the centre of a vertical
cylinder of half-height 0.9 m (a person 1.8 m tall standing on the floor, z = 0.9).

Run from the repository root: python3 scenarios/data/make_pedestrians.py
"""
import math
import random

RATE_HZ = 10.0
Z = 0.9

# (x, y, speed to get there in m/s, or None for "stand still for `pause` seconds")
WALKERS = {
    # Crosses the room along y, stands at the far wall, walks back a little further east.
    "walker_1": [(3.0, 0.4), (3.0, 5.4, 1.2), ("stop", 2.0), (3.6, 3.0, 1.1), (3.6, 0.6, 1.3),
                 ("stop", 1.5), (2.2, 2.8, 1.2), (2.2, 5.2, 1.0)],
    # Walks west along y = 4, stops, turns south and back east, ends standing near the south wall:
    # crosses the diagonal twice.
    "walker_2": [(7.5, 4.0), (4.5, 4.0, 1.3), ("stop", 1.0), (1.2, 4.0, 1.2), (1.2, 2.2, 1.0),
                 ("stop", 2.5), (6.5, 2.2, 1.4), (6.5, 0.6, 1.1)],
    # Paces around the middle of the room: a rectangle with a stop at each corner (looped).
    "walker_3": [(5.0, 1.0), (5.5, 1.0, 1.0), ("stop", 1.0), (5.5, 4.8, 1.2), ("stop", 1.0),
                 (4.2, 4.8, 1.0), ("stop", 1.0), (4.2, 1.0, 1.2), ("stop", 1.0), (5.0, 1.0, 1.0)],
}


def timeline(plan):
    """Piecewise-linear (t, x, y) knots of a plan."""
    x, y = plan[0]
    knots = [(0.0, x, y)]
    t = 0.0
    for step in plan[1:]:
        if step[0] == "stop":
            t += step[1]
        else:
            nx, ny, speed = step
            t += math.hypot(nx - x, ny - y) / speed
            x, y = nx, ny
        knots.append((t, x, y))
    return knots


def sample(knots, rng):
    rows = []
    n = int(math.floor(knots[-1][0] * RATE_HZ)) + 1
    for k in range(n):
        t = k / RATE_HZ
        for (t0, x0, y0), (t1, x1, y1) in zip(knots, knots[1:]):
            if t0 <= t <= t1:
                s = (t - t0) / (t1 - t0) if t1 > t0 else 0.0
                x, y = x0 + s * (x1 - x0), y0 + s * (y1 - y0)
                moving = (x0, y0) != (x1, y1)
                break
        if moving:
            x += rng.uniform(-0.01, 0.01)
            y += rng.uniform(-0.01, 0.01)
        rows.append((t, x, y))
    t, x, y = knots[-1]
    if rows[-1][0] < t - 1e-3:
        rows.append((t, x, y))
    if (x, y) == knots[0][1:]:
        # A closed plan (walker_3, flown with end = "loop"): end exactly where the track starts.
        rows[-1] = (rows[-1][0], rows[0][1], rows[0][2])
    return rows


def main():
    rng = random.Random(20)
    for name, plan in WALKERS.items():
        rows = sample(timeline(plan), rng)
        with open(f"scenarios/data/{name}.csv", "w") as f:
            f.write(f"# {name}: synthetic pedestrian track (scenarios/data/make_pedestrians.py), "
                    "not real data\n")
            f.write("t,x,y,z\n")
            for t, x, y in rows:
                f.write(f"{t:.3f},{x:.3f},{y:.3f},{Z}\n")
        print(name, len(rows), "samples,", f"{rows[-1][0]:.1f} s")


if __name__ == "__main__":
    main()
