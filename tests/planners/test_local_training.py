"""Local planner training: dialogue examples, frozen layers run once, progress with ETA."""

from __future__ import annotations

import json

import pytest

from emopose.planners.local.data import load_examples
from emopose.planners.local.model import CONTEXT_CHARS, ActModel, context_prefix, layers
from tests.planners.local_helpers import training_config

DIALOGUE = ({"role": "user", "content": "Can my son touch the starfish?"},
            {"role": "assistant", "content": "Of course. I could also take him behind the scenes."})


def write_jsonl(path, rows: list[dict]) -> str:
    path.write_text("".join(json.dumps(row) + "\n" for row in rows))
    return str(path)


def test_context_prefix_marks_roles_and_keeps_the_latest_turns():
    assert context_prefix(()) == ""
    assert context_prefix(DIALOGUE) == ("visitor: Can my son touch the starfish? "
                                        "guide: Of course. I could also take him behind the scenes. [SEP] ")
    turns = tuple({"role": "assistant", "content": f"turn {k} " + "word " * 15} for k in range(5))
    assert "turn 3" in context_prefix(turns) and "turn 2" not in context_prefix(turns)  # the last two turns
    long = context_prefix(({"role": "user", "content": "first " + "word " * 100},))
    assert len(long) <= CONTEXT_CHARS + len(" [SEP] ") and long.startswith("word ")  # the newest words, whole


@pytest.fixture(scope="module")
def model():
    return ActModel(training_config(trainable_layers=1, epochs=2, batch_size=4))


def test_utterance_tokens_are_read_in_context_but_located_in_the_utterance(model):
    alone, in_context = (model.tokens(["Him? Back there? Absolutely not."], h) for h in (None, [DIALOGUE]))
    assert alone.starts == in_context.starts  # character starts relative to the utterance either way
    assert in_context.inputs["input_ids"].shape[1] > alone.inputs["input_ids"].shape[1]
    first = in_context.inputs["input_ids"][0, in_context.real[0][0]]
    assert model.tokenizer.decode(first) == "him"


def test_dialogue_items_and_distractors_are_training_examples(tmp_path):
    singles = write_jsonl(tmp_path / "singles.jsonl", [
        {"id": f"s{k}", "text": f"Welcome aboard, guest {k}.", "label": "welcoming"} for k in range(6)])
    dialogues = write_jsonl(tmp_path / "dialogues.jsonl", [
        {"id": "d1", "history": list(DIALOGUE), "text": "Absolutely not.", "label": "rejecting"}])
    sequence = write_jsonl(tmp_path / "sequence.jsonl", [
        {"id": "q1", "text": "Hi Marisol, lovely to see you! Your locker is the grey one on your left.",
         "labels": ["welcoming", "pointing"], "anchors": ["Hi Marisol", "the grey one on your left"]}])
    examples = load_examples([singles, dialogues, sequence], 0, distractors=40, seed=1)
    dialogue = [e for e in examples if e.id == "d1"][0]
    assert dialogue.history == DIALOGUE and dialogue.acts[0].label == "rejecting"
    distractors = [e for e in examples if e.id.startswith("distractor-")]
    assert len(distractors) == 40 and all(e.history == DIALOGUE for e in distractors)
    assert {e.acts[0].label for e in distractors if len(e.acts) == 1} == {"welcoming"}
    # a multi-act item keeps its split and anchors after the unrelated history (history must not sway it)
    original = [e for e in examples if e.id == "q1"][0]
    assert any((e.text, e.acts, e.anchors) == (original.text, original.acts, original.anchors)
               for e in distractors)


@pytest.mark.parametrize("attention", ["sdpa", "eager"])
def test_layers_run_one_by_one_equal_the_bodys_own_forward_on_a_padded_batch(model, attention, monkeypatch):
    # training and inference run the encoder layer by layer (frozen ones cached); padding must not leak
    import torch

    monkeypatch.setattr(model.body.config, "_attn_implementation", attention)
    tokens = model.tokens(["Hi there, welcome to the lab, everyone!", "No."])
    real = tokens.inputs["attention_mask"].bool()
    with torch.no_grad():
        whole = model.body(**tokens.inputs).last_hidden_state
        hidden = model.body.embeddings(input_ids=tokens.inputs["input_ids"],
                                       token_type_ids=tokens.inputs["token_type_ids"])
        by_layer = layers(model.body, hidden, tokens.inputs["attention_mask"], model.body.encoder.layer)
    assert not real.all()  # the short text is padded
    assert torch.allclose(by_layer[real], whole[real], atol=1e-5)


def test_frozen_layers_run_once_and_every_epoch_shows_progress(model, tmp_path, capsys, monkeypatch):
    from emopose.planners.local.training import fit

    rows = [("Welcome in, everyone!", "welcoming"), ("The exit is over there.", "pointing"),
            ("No, don't touch that.", "rejecting"), ("Yes, exactly right.", "agreeing"),
            ("Hmm, I doubt it.", "doubting")]
    path = write_jsonl(tmp_path / "train.jsonl", [{"id": f"t{k}", "text": t, "label": c}
                                                  for k, (t, c) in enumerate(rows)])
    calls = {"lower": 0}
    lower = model.lower

    def counted(inputs):
        calls["lower"] += 1
        return lower(inputs)

    monkeypatch.setattr(model, "lower", counted)
    attention = model.body.config._attn_implementation
    fit(model, load_examples([path], 0), {})
    assert calls["lower"] == 2  # two batches of four, once each, for both epochs
    assert model.body.config._attn_implementation == attention  # training's eager attention is undone
    err = capsys.readouterr().err
    assert "frozen layers" in err and "epoch 1/2" in err and "epoch 2/2" in err
    assert "<" in err  # tqdm's "elapsed<remaining": the ETA


def test_the_model_keeps_which_motions_its_training_data_annotates(model, tmp_path):
    # the variant choice weighs a motion's fit more when the class head never read an act about it
    from emopose.planners.local.training import fit

    path = write_jsonl(tmp_path / "train.jsonl", [
        {"id": "a", "text": "Hi there! The exit is on your left.", "labels": ["welcoming", "pointing"],
         "anchors": ["Hi there", "on your left"], "variants": ["face_wave", "point_left"]},
        {"id": "b", "text": "No, don't touch that.", "label": "rejecting"}])
    fit(model, load_examples([path], 0), {}, progress=False)
    assert model.annotated_motions == ["face_wave", "point_left"]
    restored = ActModel(model.config)
    restored.load_state(model.state())
    assert restored.annotated_motions == ["face_wave", "point_left"]


def test_motions_the_data_never_annotates_do_not_change_what_training_learns(tmp_path):
    # the artifact is keyed by the training files alone, so the live library's other motions must not
    # shape it (they would be negatives of the variant projections)
    import torch

    from emopose.planners.local.training import fit

    path = write_jsonl(tmp_path / "train.jsonl", [
        {"id": "a", "text": "Hi there! The exit is on your left.", "labels": ["welcoming", "pointing"],
         "anchors": ["Hi there", "on your left"], "variants": ["face_wave", "point_left"]},
        {"id": "b", "text": "Good morning! Take the stairs on the right.",
         "labels": ["welcoming", "pointing"],
         "anchors": ["Good morning", "on the right"], "variants": ["open_arms", "point_forward_right"]},
        {"id": "c", "text": "Welcome aboard! The deck is up there.", "labels": ["welcoming", "pointing"],
         "anchors": ["Welcome aboard", "up there"], "variants": ["bow", "point_up"]}])
    known = {"face_wave": ("welcoming", "face wave: a wave by the face"),
             "open_arms": ("welcoming", "open arms: arms spread to greet"),
             "bow": ("welcoming", "bow: a polite bow to a guest"),
             "point_left": ("pointing", "point left: the arm points to the left"),
             "point_forward_right": ("pointing", "point forward right: the arm points ahead and right"),
             "point_up": ("pointing", "point up: the arm points at the ceiling")}
    projections = []
    for catalogue in (known, {**known, "sailor_salute": ("welcoming", "sailor salute: a greeting aboard")}):
        model = ActModel(training_config(trainable_layers=1, epochs=1, batch_size=4))
        fit(model, load_examples([path], 0), catalogue, progress=False)
        projections.append([p.weight.detach().clone() for p in model.variant_projections])
    assert not torch.equal(projections[0][0], torch.eye(projections[0][0].shape[0]))  # they were trained
    assert all(torch.equal(a, b) for a, b in zip(*projections))


def test_linear_schedule_warms_up_then_decays_to_zero():
    from emopose.planners.local.training import learning_rate_factor

    factor = learning_rate_factor(training_config(lr_schedule="linear"), 100)
    rates = [factor(step) for step in range(100)]
    assert rates[0] == pytest.approx(0.2) and rates[4] == pytest.approx(1.0)  # 5 warm-up steps
    assert all(a >= b for a, b in zip(rates[4:], rates[5:])) and rates[-1] == pytest.approx(1 / 95)
    constant = learning_rate_factor(training_config(lr_schedule="constant"), 100)
    assert {constant(step) for step in range(100)} == {1.0}


def test_the_onset_loss_targets_each_anchors_first_token_within_its_act(model, monkeypatch):
    import torch

    from emopose.planners.local.data import multi_act
    from emopose.planners.local.losses import onset_loss

    example = multi_act({"id": "o", "text": "Hi there! The exit is on your left.",
                         "labels": ["welcoming", "pointing"], "anchors": ["Hi there", "on your left"]})
    tokens = model.tokens([example.text])
    positions = {start: tokens.real[0][k] for k, start in enumerate(tokens.starts[0])}

    def peaked_at(*chars: int) -> float:
        logits = torch.full((1, tokens.inputs["input_ids"].shape[1], 1), -10.0)
        for char in chars:
            logits[0, positions[char]] = 10.0
        monkeypatch.setattr(model, "onset_head", lambda states: logits)
        return float(onset_loss(model, [example], tokens, None, [0]))

    anchors = [start for start, _ in example.anchors]
    acts = [act.start for act in example.acts]
    assert anchors[1] != acts[1]  # the pointing act starts at "The", its anchor at "on"
    assert peaked_at(*anchors) < 1e-3 < 5.0 < peaked_at(*acts)
