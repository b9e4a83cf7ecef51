"""When there is a chest light (emopose/turn/state_light.py chest_light_for, the one rule serve and the tour
share), and whose voice client it closes: stand-in resources and voice client, no DDS."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from emopose.backends.g1 import voice as voice_module
from emopose.backends.g1.chest_light import COLOURS
from emopose.clock import FakeClock
from emopose.turn.state_light import chest_light_for
from tests.robot.g1_light_helpers import wait_until


class StandInVoice:
    def __init__(self, *args) -> None:
        self.args, self.lights, self.closed = args, [], False

    def set_light(self, rgb) -> None:
        self.lights.append(tuple(rgb))

    def close(self) -> None:
        self.closed = True


def resources(backend: str, light: bool = True, voice: StandInVoice | None = None) -> SimpleNamespace:
    player = SimpleNamespace(light=light, playing=lambda clock: False)
    if voice is not None:  # player=g1: its voice client and colours
        player.voice, player.light_colours = voice, {}
    settings = SimpleNamespace(domain_id=7, network_interface="lo")
    return SimpleNamespace(player=player, clock=FakeClock(),
                           backend=SimpleNamespace(name=backend, settings=settings, failure=None))


@pytest.fixture
def made(monkeypatch) -> list[StandInVoice]:
    clients: list[StandInVoice] = []

    def make(*args) -> StandInVoice:
        clients.append(StandInVoice(*args))
        return clients[-1]

    monkeypatch.setattr(voice_module, "VoiceClient", make)
    return clients


def test_backend_g1_with_the_hosts_audio_opens_its_own_client_and_closes_it(made):
    light = chest_light_for(resources("g1"), lambda: False)
    wait_until(lambda: made and made[0].lights, "the first light request", timeout_s=5.0)
    light.close()
    assert made[0].args == (7, "lo") and made[0].lights == [COLOURS["listening"], COLOURS["off"]]
    assert made[0].closed  # opened for the light alone


def test_player_g1_shares_its_client_and_the_light_leaves_it_open(made):
    players = StandInVoice()
    light = chest_light_for(resources("mujoco", voice=players), lambda: True)
    wait_until(lambda: players.lights, "the first light request", timeout_s=5.0)
    light.close()
    assert made == [] and players.lights == [COLOURS["thinking"], COLOURS["off"]]
    assert not players.closed  # the player still speaks through it


def test_no_g1_or_player_light_false_means_no_light(made):
    assert chest_light_for(resources("mujoco"), lambda: False) is None
    assert chest_light_for(resources("g1", light=False), lambda: False) is None
    assert chest_light_for(resources("dry_run", light=False, voice=StandInVoice()), lambda: False) is None
    assert made == []
