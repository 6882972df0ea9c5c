"""The bodies' poses and twists for one publish round, as geometry_msgs doubles: read from the world's
state once (a view of C's memory, no copy) into preallocated arrays, and shared by every topic due after
the step (bodies/poses, bodies/states, /tf, markers)."""
from __future__ import annotations

import numpy as np

from collide_ros import cdr


class PoseFrame:
    """Poses (n, 7) of every body (``all_poses``, row order; markers), and the poses (``dyn_poses``) and
    twists (``dyn_twists``, (m, 6)) of the dynamic rows ``dyn_rows`` (bodies/poses, bodies/states, /tf).

    When the dynamic rows are one contiguous range (the scenes' static bodies come first or last),
    ``dyn_poses`` is a view of ``all_poses`` and its state rows a view of the world's; otherwise both
    are gathered with one np.take into buffers. The arrays are rewritten by each ``refresh``: a caller
    copies what it keeps (the CDR writers do)."""

    def __init__(self, dyn_rows: np.ndarray, count: int) -> None:
        rows = np.asarray(dyn_rows, dtype=np.int64)
        self.count = count
        self.all_poses = np.zeros((count, 7))
        self.dyn_twists = np.zeros((len(rows), 6))
        self._rows = rows
        self._range: slice | None = None
        if len(rows) == 0 or int(rows[-1]) - int(rows[0]) + 1 == len(rows):
            first = int(rows[0]) if len(rows) else 0
            self._range = slice(first, first + len(rows))
            self.dyn_poses = self.all_poses[self._range]
            self._dyn_state = np.zeros((0, 6))
        else:
            self.dyn_poses = np.zeros((len(rows), 7))
            self._dyn_state = np.zeros((len(rows), 6))

    def refresh(self, state: np.ndarray) -> None:
        """Recompute every array from ``state`` (the world's (count, 6) state)."""
        if state.shape[0] != self.count:
            raise ValueError(f"state has {state.shape[0]} rows, the frame {self.count}")
        cdr.poses_from_state(state, out=self.all_poses)
        if self._range is not None:
            dyn = state[self._range]
        else:
            dyn = np.take(state, self._rows, axis=0, out=self._dyn_state)
            np.take(self.all_poses, self._rows, axis=0, out=self.dyn_poses)
        cdr.twists_from_state(dyn, out=self.dyn_twists)
