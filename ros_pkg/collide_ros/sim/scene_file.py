"""The node's scene file, parsed once per text: the start reads it for the parameters' defaults and
for the world, and each ~/reset reads the file again but parses it only when its text changed. The
node builds every scene it loads at once, so the load skips load_scene's trial build: the node's own
build reports C's range errors with the same message and line."""
from __future__ import annotations

import collide
from collide.scene import load_scene_text, read_scene_text


class SceneFile:
    """The last scene file read, by path and text, and the Scene parsed from it."""

    def __init__(self) -> None:
        self._key: tuple[str, str] | None = None
        self._scene: collide.Scene | None = None

    def load(self, path: str) -> collide.Scene:
        """The scene in the file now (SceneError for a malformed file; C's range errors come from its
        build()): the one parsed before if the path and the text are the same, else parsed from the
        new text. The same text is the same scene; its build() makes a fresh World each time."""
        text = read_scene_text(path)
        key = (path, text)
        if self._scene is None or self._key != key:
            self._scene = None  # a bad file leaves nothing behind to be taken for it
            self._scene = load_scene_text(text, path, validate=False)
            self._key = key
        return self._scene
