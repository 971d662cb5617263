"""A toolpath generator: a raster of thousands of blended movel moves over a 20 x 20 cm area
at process speed, as a gluing or deburring program would send — the verifier's benchmark.

Shows: generating a long program from Python, blend radii chosen so that consecutive blend
spheres never overlap (r is 30 % of the shorter neighbouring segment), a constant tool
orientation (tool z pointing down).

    urdsl compile programs/toolpath.py -o toolpath.script     # 200 moves
    python bench/verify_bench.py                               # 10,000 moves
"""

from urdsl.dsl import Joints, Pose, Program

DOWN = (0.0, 3.1416, 0.0)


def raster(n: int, width: float = 0.2, step: float = 0.02, row_pitch: float = 0.005):
    """``n`` points of a boustrophedon raster starting at x = 0.35 m, y = -0.1 m."""
    per_row = round(width / step)
    points = []
    for i in range(n):
        row, column = divmod(i, per_row + 1)
        rows = round(0.2 / row_pitch)
        x = 0.35 + row_pitch * (row % rows)
        along = column if row % 2 == 0 else per_row - column
        points.append((round(x, 6), round(-0.1 + step * along, 6)))
    return points


def make_program(n: int = 10_000, v: float = 0.1) -> Program:
    """A program of ``n`` blended movels (and a movej to start) at ``v`` m/s."""
    program = Program("toolpath")
    program.movej(Joints.deg(180, -100, 110, -100, -90, 0))
    points = raster(n)
    for k, (x, y) in enumerate(points):
        before = points[k - 1] if k else None
        after = points[k + 1] if k + 1 < len(points) else None
        gaps = [abs(complex(x - p[0], y - p[1])) for p in (before, after) if p is not None]
        radius = 0.0 if after is None else round(0.3 * min(gaps), 4)
        program.movel(Pose(x, y, 0.2, *DOWN), a=1.2, v=v, r=radius)
    return program


program = make_program(200)
