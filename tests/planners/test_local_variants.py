"""The local planner's variant choice (planners/local/variants.py, variant_score.py), on hand-made vectors:
no model."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from emopose import CLASSES
from emopose.planners.local.variant_score import Features, Weights, new_projections
from emopose.planners.local.variant_training import AnnotatedAct, fit_variants
from emopose.planners.local.variants import ClassMove, VariantChooser

CATALOGUE = {"chin_stroke": ("doubting", "hmm"), "shrug": ("doubting", "who knows"),
             "palm_stop": ("rejecting", "stop"), "finger_wag": ("rejecting", "naughty")}
EVIDENCE = {name: (cls, (text,)) for name, (cls, text) in CATALOGUE.items()}  # what choose() reads
AXIS = {name: k for k, name in enumerate(CATALOGUE)}  # each motion's description is one axis of a 4-D space
NO_WORDS = (np.zeros(0, dtype=int), np.zeros(0, dtype=np.float32))
STAY, MOVE = ClassMove(annotated=0.0, new=0.0), ClassMove(annotated=2.0, new=2.0)


def describe(texts: list[str], words: dict[str, tuple] | None = None) -> Features:
    names = [next(n for n, (_, t) in CATALOGUE.items() if t == text) for text in texts]  # in their order
    rows = np.eye(4, dtype=np.float32)[[AXIS[n] for n in names]]
    return Features(rows, rows, rows, [(words or {}).get(n, NO_WORDS) for n in names])


def act_near(name: str, other: str | None = None, share: float = 0.0, words: tuple = NO_WORDS) -> Features:
    vector = np.eye(4, dtype=np.float32)[AXIS[name]] * (1 - share)
    if other:
        vector[AXIS[other]] = share
    vector = vector[None] / np.linalg.norm(vector)
    return Features(vector, vector, vector, [words])


def proba(**by_class: float) -> np.ndarray:
    return np.array([by_class.get(c, 0.0) for c in CLASSES]) + 1e-3


@pytest.fixture
def chooser():
    return VariantChooser(new_projections(4), describe, Weights(word=1.0, shared=1.0, pretrained_share=0.0),
                          frozenset(CATALOGUE))


def test_the_best_fitting_motion_of_the_class_is_chosen(chooser):
    unsure = proba(doubting=0.6, rejecting=0.4)
    chosen = chooser.choose(lambda: EVIDENCE, 1, "doubting", unsure, act_near("shrug"), STAY)
    assert chosen == ("doubting", "shrug")
    # without the class weight the class is the split model's, even when another class's motion fits
    chosen = chooser.choose(lambda: EVIDENCE, 1, "doubting", unsure, act_near("finger_wag"), STAY)
    assert chosen[0] == "doubting"


def test_a_clearly_better_motion_may_move_an_unsure_act_but_not_a_sure_one(chooser):
    scolding = act_near("finger_wag")
    assert chooser.choose(lambda: EVIDENCE, 1, "doubting", proba(doubting=0.6, rejecting=0.4), scolding,
                          MOVE) == ("rejecting", "finger_wag")
    assert chooser.choose(lambda: EVIDENCE, 1, "doubting", proba(doubting=0.999), scolding,
                          MOVE) == ("doubting", "chin_stroke")
    # an act that fits a doubting motion as well as the rejecting one keeps the likelier class
    even = act_near("chin_stroke", "finger_wag", 0.5)
    assert chooser.choose(lambda: EVIDENCE, 1, "doubting", proba(doubting=0.6, rejecting=0.4), even,
                          MOVE)[0] == "doubting"


def test_a_motion_the_training_data_never_annotated_moves_the_class_further():
    # finger_wag was added by file: the class head never read an act about it
    weights = Weights(word=1.0, shared=1.0, pretrained_share=0.0)
    chooser = VariantChooser(new_projections(4), describe, weights, frozenset(CATALOGUE) - {"finger_wag"})
    scolding, sure = act_near("finger_wag"), proba(doubting=0.999)
    assert chooser.choose(lambda: EVIDENCE, 1, "doubting", sure, scolding, MOVE)[0] == "doubting"
    # the class head was sure without knowing the new motion; its clear fit moves the act all the same
    assert chooser.choose(lambda: EVIDENCE, 1, "doubting", sure, scolding,
                          ClassMove(annotated=2.0, new=8.0)) == ("rejecting", "finger_wag")
    # the larger weight is the new motion's alone: an annotated one fitting as well moves no further
    known = VariantChooser(new_projections(4), describe, Weights(word=1.0, shared=1.0, pretrained_share=0.0),
                           frozenset(CATALOGUE))
    assert known.choose(lambda: EVIDENCE, 1, "doubting", sure, scolding,
                        ClassMove(annotated=2.0, new=8.0))[0] == "doubting"
    # however large its weight, a new motion that fits no better than the act's own class's never moves it
    even = act_near("chin_stroke", "finger_wag", 0.5)
    assert chooser.choose(lambda: EVIDENCE, 1, "doubting", proba(doubting=0.6, rejecting=0.4), even,
                          ClassMove(annotated=2.0, new=8.0))[0] == "doubting"


def test_no_weight_no_move_even_toward_a_likelier_class(chooser):
    # the split may give an act a less likely class (neighbouring acts must differ); a weight of 0 keeps it
    likelier_elsewhere = proba(doubting=0.4, rejecting=0.6)
    assert chooser.choose(lambda: EVIDENCE, 1, "doubting", likelier_elsewhere, act_near("finger_wag"),
                          STAY) == ("doubting", "chin_stroke")
    assert chooser.choose(lambda: EVIDENCE, 1, "doubting", likelier_elsewhere, act_near("finger_wag"),
                          ClassMove(annotated=0.0, new=8.0))[0] == "doubting"  # finger_wag is annotated here


def test_a_class_without_motions_or_a_neighbours_class_is_never_moved_to(chooser):
    scolding = act_near("finger_wag")
    unsure = proba(doubting=0.6, rejecting=0.4)
    # the split model's class has no motion in the library: it stays, without a motion
    chosen = chooser.choose(lambda: EVIDENCE, 1, "neutral", proba(neutral=0.99), scolding, MOVE)
    assert chosen == ("neutral", None)
    # the act next to it is already rejecting: neighbouring acts keep differing in class
    assert chooser.choose(lambda: EVIDENCE, 1, "doubting", unsure, scolding, MOVE,
                          frozenset({"rejecting"}))[0] == "doubting"


def test_a_barred_motion_is_never_chosen_in_the_class_or_across(chooser):
    # the planner bars an added pointing motion aimed a way the act does not name (direction.py)
    unsure = proba(doubting=0.6, rejecting=0.4)
    assert chooser.choose(lambda: EVIDENCE, 1, "doubting", unsure, act_near("shrug"), STAY,
                          barred=frozenset({"shrug"})) == ("doubting", "chin_stroke")
    # the best fit of the other class is barred: its runner-up (fitting no better than chin_stroke) is no move
    assert chooser.choose(lambda: EVIDENCE, 1, "doubting", unsure, act_near("finger_wag"), MOVE,
                          barred=frozenset({"finger_wag"})) == ("doubting", "chin_stroke")
    # every motion of the act's class barred: the class stays, without a motion, and nothing moves it
    assert chooser.choose(lambda: EVIDENCE, 1, "doubting", unsure, act_near("finger_wag"), MOVE,
                          barred=frozenset({"shrug", "chin_stroke"})) == ("doubting", None)


def test_a_rare_word_the_description_also_says_decides_between_motions():
    # token ids: 7 "naughty" (rare), 1 "the" (frequent); only finger_wag's description says "naughty"
    words = {"finger_wag": (np.array([7, 1]), np.array([0.9, 0.01])),
             "palm_stop": (np.array([1]), np.array([0.01]))}
    chooser = VariantChooser(new_projections(4), lambda texts: describe(texts, words),
                             Weights(word=0.0, shared=1.0, pretrained_share=0.0), frozenset(CATALOGUE))
    # the vectors lean to palm_stop; the shared rare word outweighs them
    naughty = act_near("palm_stop", "finger_wag", 0.4, (np.array([1, 7]), np.array([0.01, 0.9])))
    chosen = chooser.choose(lambda: EVIDENCE, 1, "rejecting", proba(rejecting=1.0), naughty, STAY)
    assert chosen[1] == "finger_wag"
    # sharing only a frequent word carries no weight against the vectors; a token no description has (an
    # id past every description's) counts against the share
    plain = act_near("palm_stop", "finger_wag", 0.4, (np.array([1, 5, 30000]), np.array([0.01, 0.9, 0.9])))
    chosen = chooser.choose(lambda: EVIDENCE, 1, "rejecting", proba(rejecting=1.0), plain, STAY)
    assert chosen[1] == "palm_stop"


def test_a_share_of_the_pretrained_similarity_keeps_a_motion_the_projections_lost():
    import torch

    # projections trained where no annotated act needed finger_wag's direction: they drop that axis, so
    # through them a scolding reads only as its small share of palm_stop
    projections = new_projections(4)
    with torch.no_grad():
        for projection in projections:
            projection.weight[:, AXIS["finger_wag"]] = 0.0
    scolding = act_near("finger_wag", "palm_stop", 0.1)

    def chosen(share: float) -> str | None:
        chooser = VariantChooser(projections, describe, Weights(word=0.0, shared=0.0, pretrained_share=share),
                                 frozenset(CATALOGUE))
        return chooser.choose(lambda: EVIDENCE, 1, "rejecting", proba(rejecting=1.0), scolding, STAY)[1]

    assert chosen(0.0) == "palm_stop"
    assert chosen(0.75) == "finger_wag"  # the pretrained cosines still see which description it is near


def test_an_empty_library_leaves_the_class_without_a_motion(chooser):
    chosen = chooser.choose(lambda: {}, 1, "doubting", proba(doubting=1.0), act_near("shrug"), MOVE)
    assert chosen == ("doubting", None)


def test_a_motion_scores_as_its_best_fitting_text_its_examples_included(chooser):
    act = act_near("palm_stop")  # a "stop" act of the doubting class: shrug or chin_stroke
    assert chooser.choose(lambda: EVIDENCE, 1, "doubting", proba(doubting=1.0), act, STAY)[1] != "shrug"
    with_example = EVIDENCE | {"shrug": ("doubting", ("who knows", "stop"))}  # an example reads like "stop"
    chosen = chooser.choose(lambda: with_example, 2, "doubting", proba(doubting=1.0), act, STAY)
    assert chosen == ("doubting", "shrug")


def test_an_example_the_class_head_misreads_gives_its_motion_back_what_the_head_underrates():
    # finger_wag's example "tsk tsk" lies between chin_stroke's and finger_wag's descriptions
    axes = np.eye(4, dtype=np.float32)
    vectors = {text: axes[AXIS[name]] for name, (_, text) in CATALOGUE.items()}
    vectors["tsk tsk"] = (axes[AXIS["chin_stroke"]] + axes[AXIS["finger_wag"]]) / 2 ** 0.5

    def described(texts):
        rows = np.stack([vectors[t] for t in texts])
        return Features(rows, rows, rows, [NO_WORDS] * len(texts))

    def chosen(head_reads_rejecting: float, act: Features) -> tuple:
        reads = np.full((1, len(CLASSES)), np.log(1 - head_reads_rejecting))
        reads[0, CLASSES.index("rejecting")] = np.log(head_reads_rejecting)
        chooser = VariantChooser(new_projections(4), described, Weights(1.0, 1.0, pretrained_share=0.0),
                                 frozenset(CATALOGUE), lambda texts: np.repeat(reads, len(texts), axis=0))
        evidence = EVIDENCE | {"finger_wag": ("rejecting", ("naughty", "tsk tsk"))}
        return chooser.choose(lambda: evidence, 1, "doubting", proba(doubting=0.999), act, MOVE)

    like_the_example = act_near("chin_stroke", "finger_wag", 0.5)
    assert chosen(0.99, like_the_example) == ("doubting", "chin_stroke")  # the head is right on the example
    # the head also reads finger_wag's own example as not rejecting: its doubt counts for that much less
    assert chosen(np.exp(-6.0), like_the_example) == ("rejecting", "finger_wag")
    # an act the example fits worse than the act's own class's motion gets no credit, however large
    assert chosen(np.exp(-50.0), act_near("chin_stroke", "finger_wag", 0.1)) == ("doubting", "chin_stroke")


def test_descriptions_are_read_again_when_the_library_changes(chooser):
    calls = []

    def catalogue():
        calls.append(1)
        return EVIDENCE

    for version in (1, 1, 2):
        chooser.choose(catalogue, version, "doubting", proba(doubting=1.0), act_near("shrug"), STAY)
    assert len(calls) == 2


def test_projections_learn_the_annotated_motion():
    import torch

    torch.manual_seed(0)
    axes = torch.eye(4)
    described = {n: (c, axes[AXIS[n]], axes[AXIS[n]]) for n, (c, _) in CATALOGUE.items()}
    # acts exactly between two doubting motions, annotated with the second: untrained, the tie goes to the
    # first; trained, the projections tell them apart
    between = torch.nn.functional.normalize(axes[AXIS["chin_stroke"]] + axes[AXIS["shrug"]], dim=0)
    vector = between.numpy()
    projections = new_projections(4)

    def chosen() -> str | None:
        chooser = VariantChooser(projections, describe, Weights(word=0.0, shared=0.0, pretrained_share=0.0),
                                 frozenset(CATALOGUE))
        act = Features(vector[None], vector[None], vector[None], [NO_WORDS])
        return chooser.choose(lambda: EVIDENCE, 1, "doubting", proba(doubting=1.0), act, STAY)[1]

    assert chosen() == "chin_stroke"
    acts = [AnnotatedAct("doubting", "shrug", between.clone(), between.clone()) for _ in range(64)]
    cfg = SimpleNamespace(seed=0, head_lr=0.05, batch_size=16, logit_scale=20.0, variant_holdout=0.0,
                          variant_epochs=20)
    fit_variants(projections, acts, described, cfg, progress=False)
    assert chosen() == "shrug"
