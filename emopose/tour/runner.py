"""The guided tour: walk the route, narrate each stop with gestures, answer visitors, end at rest.

Per stop: (optionally say the approach line while walking) -> drive there on odometry -> narrate.
Gestures run while standing: the arms return to neutral before every leg, and lines said while
walking are speech only unless gesture_while_walking. A question (scripted or live) at any point
stops the base, clears pending gestures with a blend, is answered through the pipeline with the
whole tour's dialogue history (and the head camera frame when it asks about the scene), and the
tour resumes: the leg from where the base stopped, the narration from the interrupted sentence.
"Stop the tour" ends it. Whatever happens, run() leaves the base stopped and the arms at neutral.
With a G1 connected the chest light follows the tour as it follows serve (emopose/turn/state_light.py:
listening, thinking from a line's request until its audio starts, speaking, fault; off when the tour ends).
"""

from __future__ import annotations

import logging
import math
from functools import partial

from emopose.contract import EventKind
from emopose.execution.gesture_command import State
from emopose.planners.base import ModalPlanner, Planner, PlannerMode
from emopose.resources import Run
from emopose.scene.view import SceneView
from emopose.tour.camera import Camera
from emopose.tour.interruptions import Interruptions, Question, asks_about_scene, wants_abort
from emopose.tour.navigator import GroundTruthBase, MobileBase, NavigationSettings, Navigator
from emopose.tour.report import Exchange, StopResult, TourReport
from emopose.tour.scenario import StopSpec, TourSpec
from emopose.tour.voice import Line, TourVoice, sentence_chunks
from emopose.tour.world import TourWorld
from emopose.turn.state_light import chest_light_for

log = logging.getLogger(__name__)

DEFAULT_ANSWER = "That is a good question; let me tell you more about it after the tour."


class TourRunner:
    """Runs one tour in `run`: its turn runner says the lines and keeps the dialogue, and the
    resources' scene slot tells the aim stage what the robot is looking at. The runner closes the camera
    it is given when the tour ends."""

    def __init__(self, run: Run, spec: TourSpec, base: MobileBase, camera: Camera,
                 interruptions: Interruptions | None = None, answer_planner: Planner | None = None) -> None:
        res = run.resources
        self.spec, self.base, self.camera = spec, base, camera
        self.turns, self.sequencer, self.scene = run.runner, res.sequencer, res.scene
        self.world = TourWorld(run.session, res.clock, base)
        self.voice = TourVoice(self.world, run.runner, res.synthesizer, res.player, res.sequencer)
        self.navigator = Navigator(base, NavigationSettings(**spec.navigation.model_dump()),
                                   self.world.advance, self.world.now, self.world.dt)
        self.interruptions = interruptions or Interruptions(spec.interruptions)
        self.answer_planner = answer_planner or res.planner
        self.report = TourReport(spec.name)
        self.open_light = partial(chest_light_for, res, lambda: self.voice.preparing)
        self.aborted = False
        self._moving_when_asked = False

    # -- the tour ----------------------------------------------------------------------------
    def run(self) -> TourReport:
        first_event = self.sequencer.events.total
        self.event("start", pose=self.base.odometry().as_dict())
        light = self.open_light()
        try:
            for stop in self.spec.stops_in_order:
                result = self.walk_to(stop)
                self.report.stops.append(result)
                if not self.aborted:
                    self.narrate(stop, result)
                if self.aborted:
                    break
            if not self.aborted and self.spec.closing:
                closing = self.say(self.spec.closing, "closing")
                self.voice.finish(closing)
                self.turns.dialogue.said(closing.text)
        finally:
            self.come_to_rest()
            self.camera.close()
            if light is not None:
                light.close()
            self.report.finish(self.sequencer.events.since(first_event), self.aborted,
                               [q.text for q in self.interruptions.unasked])
            self.event("end", aborted=self.aborted, at_rest=self.report.ended_at_rest)
        return self.report

    def walk_to(self, stop: StopSpec) -> StopResult:
        goal = stop.pose.pose()
        self.scene.view = SceneView.walking(self.base.odometry(), self.spec.objects)
        if not self.spec.gesture_while_walking:
            self.voice.to_rest()
        if stop.approach:
            if self.spec.gesture_while_walking:
                self.say(stop.approach, "approach")
            else:
                self.voice.speak_only(stop.approach, "approach")
            self.turns.dialogue.said(stop.approach)
        self.event("depart", stop=stop.name, goal=goal.as_dict())
        events_before, exchanges_before = self.sequencer.events.total, len(self.report.exchanges)
        leg = self.navigator.go_to(goal, poll=lambda t: self._poll("leg", stop.name, t), handle=self.answer)
        started = sum(e.kind == EventKind.STARTED for e in self.sequencer.events.since(events_before))
        answered = sum(len(x.gestures) for x in self.report.exchanges[exchanges_before:])  # given standing
        truth = self.base.true_pose() if isinstance(self.base, GroundTruthBase) else None
        arrived = truth or leg.odometry  # where the robot really is, when the simulator knows
        result = StopResult(
            name=stop.name, reached=leg.reached, leg_s=leg.duration_s, pauses=leg.pauses,
            odometry_error_m=leg.odometry_error_m,
            true_error_m=truth.distance_to(goal) if truth else None,
            yaw_error_deg=abs(math.degrees(arrived.heading_error_to(goal))),
            within_tolerance=arrived.distance_to(goal) <= self.spec.navigation.stop_tolerance_m,
            gestures_while_walking=started - answered)
        self.event("arrive", stop=stop.name, reached=leg.reached, odometry=leg.odometry.as_dict(),
                   true=truth.as_dict() if truth else None)
        return result

    def narrate(self, stop: StopSpec, result: StopResult) -> None:
        scene = SceneView.at(self.base.odometry(), stop, self.spec.objects)
        self.scene.view = scene
        pieces, offset = sentence_chunks(stop.narration), 0.0
        events_before = self.sequencer.events.total
        while pieces and not self.aborted:
            line = self.say(pieces.pop(0), "narration")
            # Scripted questions count time from the start of the whole narration, across its pieces.
            poll = partial(self._poll_narration, stop.name, offset)
            # Between pieces of one narration the next piece's gestures may queue behind this one's.
            question = self.voice.finish(line, poll=poll, wait_for_gestures=not pieces)
            result.narration.append(line.text)
            self.turns.dialogue.said(_spoken(line))
            offset += line.stopped_at_s if question is not None else line.speech.duration_s
            if question is None:
                continue
            result.interruptions += 1
            if line.remaining():  # resume from the sentence the question cut into
                pieces.insert(0, line.remaining())
            if not self.answer(question):
                break
            self.scene.view = scene  # the answer may have updated the view
        result.add_events(self.sequencer.events.since(events_before), scene.aims)

    # -- questions ---------------------------------------------------------------------------
    def _poll(self, where: str, stop: str, elapsed_s: float) -> Question | None:
        question = self.interruptions.poll(where, stop, elapsed_s)
        if question is not None:
            self._moving_when_asked = self.base.moving()
        return question

    def _poll_narration(self, stop: str, before_s: float, elapsed_s: float) -> Question | None:
        return self._poll("stop", stop, before_s + elapsed_s)

    def answer(self, question: Question) -> bool:
        """Answer one question; returns whether the tour carries on."""
        walking = question.where.startswith("leg") or self._moving_when_asked
        self.event("question", text=question.text, where=question.where, base_moving=self._moving_when_asked)
        self.turns.silence()
        if self.scene.view is not None:
            self.scene.view.base = self.base.odometry()
        exchange = Exchange(question.text, question.where, self.world.stream_time, self._moving_when_asked)
        events_before = self.sequencer.events.total
        if wants_abort(question.text):
            line = self.say(self.spec.abort_reply, "abort", question=question.text)
            exchange.aborted = self.aborted = True
        else:
            image = self.camera.frame_image() if asks_about_scene(question.text) else None
            exchange.image_attached = image is not None
            answerer = self.answer_planner
            if isinstance(answerer, ModalPlanner) and answerer.mode is PlannerMode.RESPOND:  # answers itself
                line = self.say(question.text, "answer", image=image, planner=self.answer_planner)
            else:  # a narrating planner gestures a prepared answer, with the question in its history
                line = self.say(question.answer or DEFAULT_ANSWER, "answer", image=image,
                                question=question.text)
        self.voice.finish(line)
        exchange.answer = line.text
        exchange.gestures = [e.name for e in self.sequencer.events.since(events_before)
                             if e.kind == EventKind.STARTED]
        self.turns.dialogue.exchange(question.text, line.text)
        self.report.exchanges.append(exchange)
        if walking and not self.spec.gesture_while_walking:
            self.voice.to_rest()
        self.event("answered", text=line.text, gestures=exchange.gestures, image=exchange.image_attached)
        return not self.aborted

    # -- helpers -----------------------------------------------------------------------------
    def say(self, text: str, kind: str, image: bytes | None = None, planner: Planner | None = None,
            question: str | None = None) -> Line:
        line = self.voice.perform(text, kind, image, planner, question)
        self.event("say", kind=kind, text=line.text, speech_s=line.speech.duration_s)
        return line

    def come_to_rest(self) -> None:
        self.navigator.halt()
        sequencer = self.sequencer
        if sequencer.active is not None or sequencer.pending:
            self.turns.silence()
        self.voice.to_rest(timeout_s=10.0)
        self.report.ended_at_rest = sequencer.state == State.IDLE and not self.base.moving()
        self.report.sim_time_s = self.world.stream_time

    def event(self, what: str, **payload) -> None:
        self.world.record("/tour/event", {"event": what, **payload})
        log.info("tour %s %s", what, payload)


def _spoken(line: Line) -> str:
    if line.stopped_at_s is None:
        return line.text
    remaining = line.remaining()
    return line.text[: len(line.text) - len(remaining)].strip() or line.text
