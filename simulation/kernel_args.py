"""The argument records of the trajectory kernels (:func:`simulation.kernel.simulate`,
:func:`simulation.kernel3d.simulate3d`).

A kernel takes a dozen records instead of some eighty arrays and scalars: the blocks of a chunk, the terrain,
the material table, the collectors, the settings and the output buffers.  Each record is a
:func:`collections.namedtuple` of numpy arrays and scalars; numba compiles it as a tuple, so a field costs nothing
to reach and the kernels unpack them into their locals.  Two arguments stay outside the records because numba
compiles a version of the kernel without their code when they are None (:func:`simulation.engine.kernel_features`):
``m_drag``, the per-material rolling drag, and ``sin_max_roll``, the steep-face limit.

Units: length m, velocity m/s, spin rad/s, mass kg, energy kJ, time s, angles deg unless a field says otherwise.
"""
from __future__ import annotations

from collections import namedtuple

#: The blocks of a 2-D chunk, one entry per block: global index ``ids`` (int64, seeds the block's random stream),
#: release position ``x``, ``z``, velocity ``vx``, ``vz``, spin ``w``, ``mass``, ``radius`` and inertia factor
#: ``k`` = I / (m r^2) [-], and ``resist`` the block's standard normal deviate of its rolling resistance angle (phi_g
#: + resist * ``phig_std`` on every material, :data:`MaterialTable`).
Blocks2D = namedtuple("Blocks2D", ["ids", "x", "z", "vx", "vz", "w", "mass", "radius", "k", "resist"])

#: The blocks of a 3-D chunk: as :data:`Blocks2D` with ``y`` and ``vy``, and ``dev`` the block's own factor of the
#: lateral deviation [-] (:func:`simulation.kernel3d_contact.deviation_sd`).
Blocks3D = namedtuple("Blocks3D", ["ids", "x", "y", "z", "vx", "vy", "vz", "w", "mass", "radius", "k", "resist",
                                   "dev"])

#: The 2-D slope section: vertices ``x``, ``z``, the chord-offset tree ``tree`` of the profile and its number of
#: leaves ``n_leaves``, the material index of each segment ``seg_mat`` and the first and last segment of each
#: segment's straight run ``run_first``, ``run_last`` (int64).
Profile2D = namedtuple("Profile2D", ["x", "z", "tree", "n_leaves", "seg_mat", "run_first", "run_last"])

#: The 3-D terrain: elevations ``z`` (ny, nx; NaN holes), the centre of cell (0, 0) at (``x0``, ``y0``), the cell
#: sizes ``dx``, ``dy``, the grid's Lipschitz bound ``lip`` [-], the material index of each cell ``mat`` and the
#: roughness of each cell ``rough`` [m] (NaN: the material's; an array of shape (0, 0): the materials' everywhere).
Grid3D = namedtuple("Grid3D", ["z", "x0", "y0", "dx", "dy", "lip", "mat", "rough"])

#: One entry per material (:func:`simulation.engine.material_table`): normal restitution law code, mean and sd
#: (``en_law``, ``en_mean``, ``en_std``), tangential law code, mean and sd (``et_law``, ``et_mean``, ``et_std``),
#: impact friction angle and its sd (``phi``, ``phi_std``) [deg], roughness ``rough`` [m], rolls (True) or slides
#: ``roll``, rolling or sliding resistance tan(phi_g) ``mu_ground`` [-], energy gain allowed ``gain``, velocity
#: scale of e_N ``en_v0`` [m/s] (inf: none), hop height ``hop`` [m], the rolling resistance's size coefficient
#: ``size_k`` [-], cap ``mu_cap`` [-] and exponent ``size_exp`` [-], the tangential scaling's velocity scale
#: ``et_v0`` [m/s] (inf: none), phi_g itself ``phig`` [deg] and its spread between blocks ``phig_std`` [deg] (0:
#: none), and the lateral deviation's gain ``dev`` [-] and speed scale ``dev_v`` [m/s] (3-D kernel only).  The laws
#: are those of :mod:`simulation.contact`.
MaterialTable = namedtuple("MaterialTable", ["en_law", "en_mean", "en_std", "et_law", "et_mean", "et_std", "phi",
                                             "phi_std", "rough", "roll", "mu_ground", "gain", "en_v0", "hop", "size_k",
                                             "mu_cap", "size_exp", "et_v0", "phig", "phig_std", "dev",
                                             "dev_v"])

#: The 2-D collectors: position ``x``, barrier capacity ``cap`` [kJ] and height ``h`` (NaN: a plain collector), and
#: ``order`` (int64) the collectors by increasing x, the order a block moving downslope crosses them.
Collectors2D = namedtuple("Collectors2D", ["x", "cap", "h", "order"])

#: The 3-D collectors, one entry per plan segment: its ends (``ax``, ``ay``) - (``bx``, ``by``), the collector it
#: belongs to ``id`` (int64), its start along the collector's line ``s0``, the barrier's capacity ``cap`` [kJ]
#: (inf: holds every block below its top) and net height ``net`` (NaN: a plain collector).
Collectors3D = namedtuple("Collectors3D", ["ax", "ay", "bx", "by", "id", "s0", "cap", "net"])

#: The 2-D envelope: bin centres ``x`` and the accumulator ``acc`` (bins, 7): count, max and sum of speed [m/s],
#: height [m] and energy [kJ].
Envelope2D = namedtuple("Envelope2D", ["x", "acc"])

#: The run's scalars: gravity ``g`` [m/s^2], the numerical floor of the contact speed ``v_contact`` and the stop
#: speed ``v_stop`` [m/s], the largest number of events per block ``max_events``, the random key of the run ``key``
#: (numpy.uint64) and ``n_path_blocks``: the paths of the blocks with index below it are recorded.
KernelSettings = namedtuple("KernelSettings", ["g", "v_contact", "v_stop", "max_events", "key", "n_path_blocks"])

#: Output per 2-D block: stop position ``x``, ``z``, stop reason code ``reason`` (``STOP_REASONS``), number of
#: impacts ``impacts`` and travel time ``t``.
Stops2D = namedtuple("Stops2D", ["x", "z", "reason", "impacts", "t"])

#: Output per 3-D block: as :data:`Stops2D` with ``y``, the largest rise of the total energy between events
#: ``excess`` [J] (a check of the integration) and the number of events ``events``.
Stops3D = namedtuple("Stops3D", ["x", "y", "z", "reason", "impacts", "t", "excess", "events"])

#: Output per 2-D crossing: block and collector index (``block``, ``coll``), time ``t``, velocity ``vx``, ``vz``, spin
#: ``w``, height of the centre above the ground ``h``, outcome code ``outcome`` (``OUTCOMES``), and ``count`` (int64,
#: 2): crossings written and crossings that did not fit.
Crossings2D = namedtuple("Crossings2D", ["block", "coll", "t", "vx", "vz", "w", "h", "outcome", "count"])

#: Output per 3-D crossing: as :data:`Crossings2D` with the distance along the collector ``s`` and the plan position
#: ``x``, ``y`` and ``vy``.
Crossings3D = namedtuple("Crossings3D", ["block", "coll", "s", "t", "x", "y", "vx", "vy", "vz", "w", "h", "outcome",
                                         "count"])

#: Output per pixel passage of a 3-D block (hazard rasters): block, cell index, energy [kJ] and height [m], and
#: ``count`` (int64, 2): passages written and passages that did not fit.
Passages3D = namedtuple("Passages3D", ["block", "cell", "e", "h", "count"])

#: Output per 2-D path point: block, time, position, velocity, spin, mode and event code, and ``count`` (int64, 1):
#: points written.
Paths2D = namedtuple("Paths2D", ["block", "t", "x", "z", "vx", "vz", "w", "mode", "event", "count"])

#: Output per 3-D path point: block, time, position, speed and mode, and ``count`` (int64, 1): points written.
Paths3D = namedtuple("Paths3D", ["block", "t", "x", "y", "z", "v", "mode", "count"])
