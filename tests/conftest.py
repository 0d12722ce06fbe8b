"""Shared test setup: Warp initialised once per session, without its banner."""

import pytest
import warp as wp


@pytest.fixture(scope="session", autouse=True)
def warp_quiet():
    wp.config.quiet = True
    wp.init()
