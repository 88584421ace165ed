"""The compiled kernels the suite uses, compiled once into numba's on-disk cache before the test processes need them.

On a machine whose cache is cold (CI's fresh clone), each of the two pytest-xdist processes compiled every kernel
specialisation it met first (the 2-D kernel ``simulation.kernel.simulate`` in its four specialisations, with and
without rolling drag and steep faces, and the 3-D kernel), mostly the same ones at the same time: the same machine
code compiled twice.  ``tests/conftest.py`` starts two children of this module from the pytest-xdist controller,
each compiling a different half (``python -m tests.kernel_warmup HALF DONE_FILE``, HALF 0 or 1), while the test
processes start and collect; each test process waits for both children before its first test, then loads the
kernels from the cache.
Nothing is checked here: a child that fails only means the kernel is compiled on first use, as without it.
"""
from __future__ import annotations

import sys
from pathlib import Path


def kernel_2d(drag: bool, steep: bool) -> None:
    """Compile (or load) the 2-D kernel's specialisation with rolling drag ``drag`` and steep faces ``steep``:
    :func:`simulation.kernel.simulate` called on no blocks with the argument types :func:`simulation.engine.run`
    passes (``m_drag`` a float array or None, ``sin_max_roll`` a float or None)."""
    import numpy as np

    from simulation import kernel
    from simulation.precompile import empty_kernel_arguments
    args = empty_kernel_arguments()
    if drag:
        args["m_drag"] = np.zeros(0)
    if steep:
        args["sin_max_roll"] = 0.5
    kernel.simulate(**args)


def kernel_3d() -> None:
    """Compile (or load) the 3-D kernel and its helpers: five blocks on a 35 degree plane."""
    import numpy as np

    import simulation
    tan = np.tan(np.radians(35.0))
    ter = simulation.Terrain.from_function(lambda x, y: 100 - tan * x, (0, 60), (0, 20), 1.0)
    sc = simulation.terrain_scenario_from_dict(
        {"terrain": {}, "materials": {"rock": {"normal_restitution": 0.3, "tangential": {"law": "constant",
                                                                                           "mean": 0.8},
                                                "roughness_m": 0.0, "ground_friction_angle_deg": 33.0}},
         "sources": {"points": [[5.0, 10.0]], "height_m": 1.0, "mass_kg": 1000},
         "collectors": [{"name": "line", "line": [[40.0, 0.0], [40.0, 20.0]]}]}, terrain=ter)
    simulation.run_terrain(sc, 5, seed=1)


#: The two halves, about equal in compilation time (CPU seconds measured on a loaded 2-core machine, cold cache):
#: three of the 2-D kernel's specialisations (without drag and steep faces, the most used, 13 s with the contact
#: helpers; with both 9 s; with steep faces only 9 s), and the fourth (drag only, 9 s) with the 3-D kernel (20 s).
HALVES = ((lambda: kernel_2d(False, False), lambda: kernel_2d(True, True), lambda: kernel_2d(False, True)),
          (lambda: kernel_2d(True, False), kernel_3d))


def main(half: int, done: Path) -> None:
    """Compile half ``half`` (0 or 1), then create the file ``done`` whatever happened."""
    try:
        for compile_one in HALVES[half]:
            try:
                compile_one()
            except Exception:           # noqa: BLE001 -- the test that uses the kernel reports it
                pass
    finally:
        done.touch()


if __name__ == "__main__":
    main(int(sys.argv[1]), Path(sys.argv[2]))
