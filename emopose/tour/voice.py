"""Saying things on the tour: plan a line into gestures, speak it, and wait for it to finish.

perform() runs the line as a turn through the turn runner; the tour pipeline (conf/pipeline/tour.yaml)
dispatches without blocking, so it returns once the gestures are queued against the speech start, and
finish() then advances the world until the speech has ended and the arms have settled, polling for a
visitor's question, which cuts the line short. speak_only() is speech without gestures (lines said
while walking). `preparing` is true from a line's request until its audio starts (planning, synthesis,
the timeline): the chest light's "thinking", with no "listening" flicker before the robot speaks.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass

from emopose.contract import MAX_REPLY_CHARS
from emopose.execution.sequencer import Sequencer, State
from emopose.planners.base import Planner
from emopose.sentences import sentence_span, split_sentences
from emopose.speech.clip import SpeechClip, Synthesizer
from emopose.speech.player import Player
from emopose.tour.interruptions import Question
from emopose.tour.world import TourWorld
from emopose.turn.model import Turn
from emopose.turn.runner import TurnRunner


def sentence_chunks(text: str, limit: int = MAX_REPLY_CHARS) -> list[str]:
    """Whole sentences packed into pieces of at most `limit` characters (a longer sentence is cut at words):
    a plan's reply holds no more, so a longer line is planned and spoken piece by piece."""
    chunks: list[str] = []
    for sentence in split_sentences(text):
        while len(sentence) > limit:  # rare: one very long sentence
            cut = sentence.rfind(" ", 0, limit)
            cut = cut if cut > 0 else limit
            chunks.append(sentence[:cut].strip())
            sentence = sentence[cut:].strip()
        if chunks and len(chunks[-1]) + 1 + len(sentence) <= limit:
            chunks[-1] = f"{chunks[-1]} {sentence}"
        else:
            chunks.append(sentence)
    return chunks


@dataclass
class Line:
    kind: str  # narration | answer | approach | closing | abort
    text: str  # what was said
    speech: SpeechClip
    speech_start: float
    turn: Turn | None = None
    stopped_at_s: float | None = None  # into the speech, when a question cut it short

    def remaining(self) -> str:
        """The text from the sentence that was being spoken when the line was cut short."""
        if self.stopped_at_s is None or self.stopped_at_s >= self.speech.duration_s:
            return ""
        start, _ = sentence_span(self.text, _char_at(self.speech, self.stopped_at_s))
        return self.text[start:].strip()


def _char_at(speech: SpeechClip, t: float) -> int:
    spoken = [w for w in speech.words if w.start_s <= t]
    if spoken:
        return spoken[-1].char_start
    return int(len(speech.text) * t / max(speech.duration_s, 1e-9))  # the anchor rule's linear map


class TourVoice:
    def __init__(self, world: TourWorld, turns: TurnRunner, synthesizer: Synthesizer, player: Player,
                 sequencer: Sequencer) -> None:
        self.world, self.turns = world, turns
        self.synthesizer, self.player, self.sequencer = synthesizer, player, sequencer
        self.preparing = False  # a line is being planned or synthesized (read by the chest light's thread)

    @contextmanager
    def _preparing(self) -> Iterator[None]:
        self.preparing = True
        try:
            yield
        finally:
            self.preparing = False

    def perform(self, utterance: str, kind: str, image: bytes | None = None, planner: Planner | None = None,
                question: str | None = None) -> Line:
        """Plan `utterance` (with the dialogue so far, and the visitor's `question` it answers) and start
        saying it with its gestures."""
        # The tour adds to the dialogue itself once a line has been said: a narration line is the robot's
        # own (no visitor said it), and a line cut short counts only as far as it was spoken.
        with self._preparing():
            turn = self.turns.run(utterance, image, planner=planner, question=question, remember=False)
        return Line(kind, turn.plan.reply, turn.speech, turn.dispatched.speech_start, turn)

    def speak_only(self, text: str, kind: str) -> Line:
        with self._preparing():
            speech = self.synthesizer.synthesize(text)
            start = self.player.play(speech, self.world.clock)
        self.world.record("/tour/speech", {"kind": kind, "text": text, "duration_s": speech.duration_s})
        return Line(kind, text, speech, start)

    def finish(self, line: Line, poll: Callable[[float], Question | None] | None = None,
               wait_for_gestures: bool = True, timeout_s: float = 120.0) -> Question | None:
        """Advance until the line is spoken (and its gestures done); a polled question stops it early."""
        sequencer, end = self.sequencer, line.speech_start + line.speech.duration_s
        deadline = self.world.now() + timeout_s
        while self.world.now() < deadline:
            now = self.world.now()
            if now >= end and (not wait_for_gestures or sequencer.settled()):
                return None
            question = poll(now - line.speech_start) if poll is not None else None
            if question is not None:
                line.stopped_at_s = now - line.speech_start
                self.turns.silence()
                return question
            self.world.advance()
        return None

    def to_rest(self, timeout_s: float = 5.0) -> bool:
        """Bring the arms back to neutral now (skipping the hold) and wait until they are there."""
        sequencer = self.sequencer
        if sequencer.state == State.HOLDING and sequencer.settled():
            sequencer.interrupt([], now=self.world.now())
        return self.world.run_until(lambda: sequencer.state == State.IDLE and sequencer.settled(), timeout_s)
