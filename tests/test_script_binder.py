"""The one call binder: laws of binding, one message per mistake, and the same wording in the
linter, the interpreter and the DSL."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from urdsl import parse
from urdsl.dsl import DslError, Program
from urdsl.lint import build_settings, lint_text
from urdsl.runtime import Interpreter
from urdsl.script.binder import Binding, Signature, first_problem, problems
from urdsl.script.builtins import lookup

NAMES = st.lists(st.from_regex(r"[a-z][a-z0-9_]{0,6}", fullmatch=True), min_size=0,
                 max_size=7, unique=True)


@st.composite
def signatures(draw) -> Signature:
    params = tuple(draw(NAMES))
    required = tuple(draw(st.lists(st.booleans(), min_size=len(params),
                                   max_size=len(params))))
    return Signature("f", params, required)


@st.composite
def valid_calls(draw):
    """A signature and a call built from it: some positional arguments, then some of the
    remaining parameters by name (every required one among them)."""
    signature = draw(signatures())
    count = draw(st.integers(0, len(signature.params)))
    rest = [(p, needed) for p, needed in zip(signature.params, signature.required,
                                             strict=True)][count:]
    named = [p for p, needed in rest if needed or draw(st.booleans())]
    return signature, count, tuple(draw(st.permutations(named)))


@given(valid_calls())
def test_a_call_built_from_its_signature_binds(case):
    signature, count, keywords = case
    assert problems(signature, count, keywords) == []
    binding = signature.bind(count, keywords)
    assert isinstance(binding, Binding)
    assert binding.positional == signature.params[:count]
    given_names = set(binding.positional) | set(keywords)
    assert {name for _, name in binding.defaulted} == set(signature.params) - given_names
    assert all(signature.params[i] == name for i, name in binding.defaulted)


@given(valid_calls(), st.sampled_from(["too-many", "twice", "unknown-keyword", "missing"]),
       st.data())
def test_one_mistake_gives_one_message(case, kind, data):
    signature, count, keywords = case
    if kind == "too-many":
        if count < len(signature.params):  # extra positionals need every parameter filled
            count, keywords = len(signature.params), ()
        count += 1
    elif kind == "twice":
        if count == 0:
            return
        keywords = (*keywords, data.draw(st.sampled_from(signature.params[:count])))
    elif kind == "unknown-keyword":
        keywords = (*keywords, "zz_" + data.draw(st.from_regex(r"[a-z]{1,4}", fullmatch=True)))
    else:
        given_names = set(signature.params[:count]) | set(keywords)
        required = [p for p, needed in zip(signature.params, signature.required, strict=True)
                    if needed and p in keywords]
        if not required:
            return
        dropped = data.draw(st.sampled_from(required))
        keywords = tuple(k for k in keywords if k != dropped)
        assert dropped in given_names
    found = problems(signature, count, keywords)
    assert [problem.kind for problem in found] == [kind]
    assert first_problem(signature, count, keywords) == found[0]
    assert found[0].message.startswith(("f() ", "argument '"))


MOVEJ = "movej([0, -1.57, 0, -1.57, 0, 0], speed=1.0)\n"
DEF_CALL = "def f(a, b=1):\n  return a + b\nend\nx = f(1, 2, 3)\n"


def _lint_message(text: str, code: str, **settings) -> tuple[str, str | None]:
    found = [d for d in lint_text(text, "t.script", build_settings(**settings)) if d.code == code]
    assert len(found) == 1, found
    return found[0].message, found[0].hint


def _runtime_message(text: str) -> tuple[str, str | None]:
    error = Interpreter(parse(text, "t.script")).run().error
    assert error is not None
    return error.message, error.hint


@pytest.mark.parametrize(("text", "code"), [
    (MOVEJ, "URS106"),
    (DEF_CALL, "URS105"),
    ("def f(a, b=1):\n  return a + b\nend\nx = f(b=2)\n", "URS107"),
    ("def f(a):\n  return a\nend\nx = f(1, a=2)\n", "URS105"),
    ("textmsg(\"a\", \"b\", \"c\")\n", "URS105"),
])
def test_linter_and_interpreter_say_the_same(text, code):
    assert _lint_message(text, code) == _runtime_message(text)


def test_the_dsl_says_the_same():
    with pytest.raises(DslError) as caught:
        Program().call("movej", [0, -1.57, 0, -1.57, 0, 0], speed=1.0)
    assert (caught.value.message, caught.value.hint) == _lint_message(MOVEJ, "URS106")
    program = Program()
    with program.function("f", "a", b=1):
        program.return_(1)
    with pytest.raises(DslError) as caught:
        program.call("f", 1, 2, 3)
    assert caught.value.message == _lint_message(DEF_CALL, "URS105")[0]


def test_wordings():
    movej = lookup("movej").call_signature
    assert first_problem(movej, 1, ("speed",)).hint == (
        "did you mean `v`? the signature is movej(q, a=1.4, v=1.05, t=0, r=0)")
    assert first_problem(movej, 6, ()).message == "movej() takes at most 5 arguments, 6 given"
    assert first_problem(movej, 2, ("a",)).message == (
        "argument 'a' of movej() is given twice, by position and by name")
    assert first_problem(movej, 0, ()).message == "movej() is missing the argument 'q'"
    two = Signature("g", ("x", "y"), (True, True))
    assert first_problem(two, 0, ()).message == "g() is missing the arguments 'x', 'y'"
    assert first_problem(lookup("struct").call_signature, 1, ()).message == (
        "struct() takes only name=value arguments")


def test_a_call_site_is_bound_once():
    signature = Signature("h", ("a", "b"), (True, False))
    first = signature.bind(1, ("b",))
    assert signature.bind(1, ("b",)) is first


def test_check_runs_cb3_code_and_unsimulated_catalog_rows(tmp_path, capsys):
    # speedj's CB3 keyword reaches the simulated speedj as its t; builtins urdsl does not
    # simulate give a neutral value and one event per call site, never an error
    from urdsl.cli import main

    program = tmp_path / "cb3.script"
    program.write_text("speedj([0.1, 0, 0, 0, 0, 0], 2.0, t_min=0.5)\nstopj(2.0)\n"
                       "i = 0\nwhile i < 3:\n  varmsg(\"i\", i)\n  i = i + 1\nend\n"
                       "p = tool_pose()\nset_runstate_outputs([])\n")
    status = main(["check", str(program), "--json", "--no-self-collision"])
    import json

    report = json.loads(capsys.readouterr().out)
    assert status == 0, report
    assert report["moves"][0]["duration"] >= 0.5
    unsupported = [e["message"] for e in report["events"] if e["kind"] == "unsupported"]
    assert unsupported == ["varmsg() is not simulated; it did nothing here",
                           "tool_pose() is not simulated; it did nothing here",
                           "set_runstate_outputs() is not simulated; it did nothing here"]
