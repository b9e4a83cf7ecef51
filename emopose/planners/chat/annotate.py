"""planner=annotate: any chat model speaks, the robot's own gesture planner annotates (beyond the paper).

respond mode: a chat model (any litellm model string) writes the reply as plain spoken text from the
dialogue history and the camera image (prompts/annotate.md); the annotator, the robot-side gesture
planner (planner=local by default), then plans that reply: classes, variants, intensities, and
triggers that are exact spans of it, so the say-do check holds by construction. Nothing asks the chat
model for JSON, so small or JSON-weak models become usable.
narrate mode: the line is given, so no model is asked: the annotator plans the line itself.
stream=true (respond mode): the reply streams in (litellm stream=True) and is cut into sentences as
they complete; each is annotated on its own and handed on (SentencePlans) while the model writes on.
If the stream fails before its first sentence the turn falls back as plan() does; after it, the
failure is raised (what was said stays said).
Either way the reply is bounded (planner.max_sentences, planner.max_speech_s; stated in the prompt,
enforced by reply_bound.py): a reply that runs long ends at a sentence boundary, and a stream that runs
long is closed there.
"""

from __future__ import annotations

import inspect
import json
import logging
import time
from collections.abc import Callable, Iterator, Sequence

from emopose.library import MotionLibrary
from emopose.llm.client import LLMClient
from emopose.llm.errors import LLMCallError
from emopose.llm.stream import TextStream
from emopose.planners.base import ModalPlanner, Planner, PlannerMode, PlannerOutput, PlanRequest, plan_all
from emopose.planners.chat.planner import ChatPlanner
from emopose.planners.chat.prompting import dialogue_demonstrations
from emopose.planners.chat.reply_bound import ReplyBound, ReplyTally
from emopose.planners.streaming import SentencePlans
from emopose.sentences import SentenceSplitter

log = logging.getLogger(__name__)


def built_annotator(annotator: Planner | Callable[..., Planner], library: MotionLibrary) -> Planner:
    """The annotator; a factory (a Hydra `_partial_` node) is given the library if its planner asks for
    one, as the build gives the run's planner."""
    if isinstance(annotator, Planner):
        return annotator
    wants_library = "library" in inspect.signature(annotator).parameters
    return annotator(library=library) if wants_library else annotator()


class AnnotatePlanner(ChatPlanner, ModalPlanner):
    """`annotator`: a Planner, or a factory of one (see built_annotator). `stream`: speak sentence by
    sentence; `stream_preroll_s`: the most the first sentence's speech waits for its first gesture to
    prepare (the timeline's max_preroll_s for that sentence: speech starts sooner); `max_sentences`,
    `max_speech_s`: the bound on a reply."""

    name = "annotate"

    def __init__(self, library: MotionLibrary, client: LLMClient, template: str, demonstrations: str,
                 annotator: Planner | Callable[..., Planner], mode: str = "respond", stream: bool = False,
                 stream_preroll_s: float = 0.0, max_demonstrations: int | None = None,
                 max_sentences: int = 3, max_speech_s: float = 12.0) -> None:
        super().__init__(client, template, demonstrations, max_demonstrations)
        if stream_preroll_s < 0:
            raise ValueError(f"planner.stream_preroll_s = {stream_preroll_s} must be >= 0")
        self.mode = PlannerMode.parse(mode)
        self.narrates = self.mode is PlannerMode.NARRATE
        self.streams, self.stream_preroll_s = bool(stream) and not self.narrates, float(stream_preroll_s)
        self.bound = ReplyBound(max_sentences, max_speech_s)
        self.template.require("demonstrations", "max_sentences", "max_speech_s",
                              hint="planner=annotate uses prompts/annotate.md.")
        self._system = self.template.render(demonstrations=dialogue_demonstrations(self.demonstrations),
                                            max_sentences=self.bound.max_sentences,
                                            max_speech_s=f"{self.bound.max_speech_s:g}")
        self.annotator = built_annotator(annotator, library)

    def system_prompt(self) -> str:
        return self._system

    def check(self) -> None:
        if not self.narrates:  # narration never asks the chat model
            super().check()

    def to_contract(self, text: str, request: PlanRequest) -> str:
        """The spoken reply (within the bound), planned by the annotator as a line that answers the
        person's words."""
        reply = self.bound.bounded(text)
        if not reply:
            return ""  # parse reports it as an empty answer
        heard = ({"role": "user", "content": request.utterance},)
        annotated = json.loads(self.annotator.plan(PlanRequest(reply, history=request.history + heard)).raw)
        return json.dumps({**annotated, "reply": reply})

    def plan(self, request: PlanRequest) -> PlannerOutput:
        if self.narrates:
            return self.annotator.plan(request)
        return super().plan(request)

    def plan_many(self, requests: Sequence[PlanRequest],
                  on_done: Callable[[], None] | None = None) -> list[PlannerOutput]:
        if self.narrates:
            return plan_all(self.annotator, requests)  # fast: the progress line advances per chunk
        return super().plan_many(requests, on_done)

    def stream(self, request: PlanRequest) -> SentencePlans:
        text = TextStream(self.client, self.messages(request))
        return SentencePlans(self._sentences(text, request), text.cancel)

    def _sentences(self, text: TextStream, request: PlanRequest) -> Iterator[PlannerOutput]:
        started, splitter, count, tally = time.perf_counter(), SentenceSplitter(), 0, self.bound.tally()
        try:
            for piece in text:
                for sentence in splitter.feed(piece):
                    if not tally.admit(sentence):
                        self._close_long(text, tally)
                        return
                    yield self._sentence(sentence, count, text, request, started)
                    count += 1
                if tally.full:
                    self._close_long(text, tally)
                    return
            rest = splitter.flush()
            if rest and not text.cancelled and tally.admit(rest):
                yield self._sentence(rest, count, text, request, started)
        except LLMCallError as exc:
            if count:
                raise
            yield self._fallback(request, exc, self.client.pass_index, time.perf_counter() - started)

    def _close_long(self, text: TextStream, tally: ReplyTally) -> None:
        """The reply reached its bound: end it at this sentence boundary and close the stream."""
        text.cancel()
        log.info("annotate: reply ended at its bound (%d sentences, %.1f s of speech; planner.max_sentences "
                 "%d, planner.max_speech_s %g); stream closed", tally.sentences, tally.speech_s,
                 self.bound.max_sentences, self.bound.max_speech_s)

    def _sentence(self, sentence: str, index: int, text: TextStream, request: PlanRequest,
                  started: float) -> PlannerOutput:
        complete = time.perf_counter()
        raw = self.to_contract(sentence, request)
        done = time.perf_counter()
        meta = {"model": self.client.model, "sentence": index, "attempts": text.attempts,
                "first_token_s": text.first_token_s, "sentence_s": complete - started,
                "annotate_s": done - complete}
        return PlannerOutput(raw=raw, latency_s=done - started, meta=meta)
