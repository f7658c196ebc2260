"""Shared test settings and helpers: the hypothesis profile sized for a 2-core CI machine, and
``outcome``, the tally of property tests whose examples may be refused."""

import os
from collections import Counter

import pytest
from hypothesis import HealthCheck, event, settings

settings.register_profile(
    "default",
    max_examples=150,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
settings.register_profile(
    "ci", max_examples=150, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
settings.load_profile("ci" if os.environ.get("CI") else "default")

#: Reprs that must never reach a message (plain numbers only).
NUMPY_REPRS = ("np.", "array(", "dtype")


class Outcomes:
    """Runs each example's ``call``: its result, or None when it refused with a clear ValueError.

    Any other exception fails the test (it propagates); a refusal must show plain numbers. The
    tally is checked when the test ends: a property test whose examples were all refused proves
    nothing, so at least ``minimum_built`` of them (default: one in twenty, and three) must have built.
    """

    def __init__(self) -> None:
        self.tally: Counter[str] = Counter()
        self.minimum_built: float = 0.05

    def __call__(self, call):
        try:
            result = call()
        except ValueError as error:
            message = str(error)
            assert message and not any(r in message for r in NUMPY_REPRS), message
            event(f"refused: {type(error).__name__}: {message[:60]}")
            self.tally["refused"] += 1
            return None
        event("built")
        self.tally["built"] += 1
        return result


@pytest.fixture
def outcome():
    """An ``Outcomes`` for one property test; its teardown asserts that enough examples were built."""
    outcomes = Outcomes()
    yield outcomes
    total = outcomes.tally["built"] + outcomes.tally["refused"]
    if total:
        assert outcomes.tally["built"] >= max(3, outcomes.minimum_built * total), (
            f"only {outcomes.tally['built']} of {total} examples were built: the property was hardly tested"
        )
