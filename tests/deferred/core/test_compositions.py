"""Compositions: the begin and end passes of a group of object passes composed together go
around every run of its members, so a pass of another kind between members splits them."""

from deferred.core.passes import BEGIN, END, Phase, RenderPass, compose_runs, without_brackets


class Marker(RenderPass):
    def __init__(self, name, composition=None, brackets=None):
        self.name = name
        self.phase = Phase.MATERIAL
        self.composition = composition
        self.brackets = brackets

    def execute(self, frame):
        pass


def names(passes):
    return [p.name for p in passes]


def test_begin_and_end_go_around_each_run_of_members():
    clear, resolve = Marker("clear", brackets=("g", BEGIN)), Marker("resolve", brackets=("g", END))
    a, b, c = (Marker(n, composition="g") for n in "abc")
    fur, last = Marker("fur"), Marker("last")
    passes = [clear, resolve, a, b, fur, c, last]
    composed = compose_runs(passes)
    assert names(composed) == ["clear", "a", "b", "resolve", "fur", "clear", "c", "resolve",
                               "last"]
    assert compose_runs(composed) is composed  # already so: the same list
    assert names(compose_runs([fur, a, b, c], brackets=passes)) == \
        ["fur", "clear", "a", "b", "c", "resolve"]
    assert without_brackets(composed) == [a, b, fur, c, last]
    # once around the span, for the list the pass graph checks
    assert names(compose_runs(passes, split=False)) == ["clear", "a", "b", "fur", "c", "resolve",
                                                        "last"]


def test_members_without_their_composition_s_passes_compose_alone():
    a = Marker("a", composition="g")
    passes = [Marker("x"), a]
    assert compose_runs(passes) is passes
