"""The system tests' marker: ``slow`` (minutes; `make test` skips them with -m 'not slow', `make test-slow` runs
them), registered here too so that running this folder alone knows it."""


def pytest_configure(config):
    config.addinivalue_line("markers", "slow: minutes long; `make test` skips them (-m 'not slow')")
