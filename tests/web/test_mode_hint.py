"""The page's mode hint before the first turn: whether the robot says the visitor's text (issue 31 item 5)."""

from __future__ import annotations

from dataclasses import dataclass

from emopose.planners.base import PlannerMode
from emopose.planners.baselines.keyword import KeywordPlanner
from emopose.web.session import narrates


@dataclass
class ModalStub:
    mode: PlannerMode
    name: str = "stub"
    sampled: bool = False

    def plan(self, request):
        raise NotImplementedError


def test_a_planner_without_a_mode_narrates():
    assert narrates(KeywordPlanner()) is True


def test_a_modal_planner_says_what_its_mode_is():
    assert narrates(ModalStub(PlannerMode.NARRATE)) is True
    assert narrates(ModalStub(PlannerMode.RESPOND)) is False
