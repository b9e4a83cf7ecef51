import pytest

from emopose.contract import GestureRecord
from emopose.library import MotionLibrary
from emopose.stages.modulate import modulate_keyframes
from emopose.turn.model import ModulatedGesture, ResolvedGesture
from tests.wiring import wire


@pytest.fixture
def wired(library, tmp_path):
    built = wire(library, tmp_path)
    with built.session:
        yield built


def gesture(library: MotionLibrary, name: str, intensity: int = 3) -> ModulatedGesture:
    """A library motion resolved exactly and modulated, as the pipeline would hand it to the schedule."""
    entry = library.get(name)
    resolved = ResolvedGesture(GestureRecord(cls=entry.cls, variant=name, intensity=intensity), entry,
                               "exact")
    return ModulatedGesture(resolved, modulate_keyframes(entry.q, intensity, library.limits),
                            entry.default_duration)
