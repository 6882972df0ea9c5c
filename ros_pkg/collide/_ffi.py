"""Loads the compiled cffi module (building it first if it is missing or stale) and maps C errors."""
from __future__ import annotations

from typing import Any

from . import build_ffi

# In a source checkout the extension is built (or refreshed) against LIBCOLLIDE_BUILD_DIR's library;
# an installed wheel carries both, side by side in this directory (the extension's RUNPATH is $ORIGIN).
if build_ffi.in_source_checkout():
    try:
        if not build_ffi.is_up_to_date():
            build_ffi.ensure_built()
    except build_ffi.BuildError as _exc:  # pragma: no cover - depends on the machine state
        raise ImportError(f"collide: cannot build the C extension: {_exc}") from _exc

from ._collide_cffi import ffi, lib  # noqa: E402  (the build above must run first)

__all__ = ["ffi", "lib", "CollideError", "check", "status_name"]


def status_name(status: int) -> str:
    """The C library's short text for a status code."""
    return ffi.string(lib.lc_status_string(status)).decode()


class CollideError(Exception):
    """A libcollide call failed. ``status`` is the lc_status code, ``message`` the C message."""

    def __init__(self, status: int, message: str) -> None:
        self.status = int(status)
        self.status_name = status_name(self.status)
        self.message = message
        super().__init__(f"{message} [{self.status_name}]" if message else self.status_name)


def check(world: Any, status: int) -> None:
    """Raise CollideError with the world's last error message when status is not LC_OK."""
    if status != lib.LC_OK:
        msg = ffi.string(lib.lc_world_last_error(world)).decode() if world is not None else ""
        raise CollideError(status, msg)
