# Convenience targets; the README's two commands are what they run.
PY ?= python3

.PHONY: demo test conformance bench experiment
demo:
	$(PY) -m pip install -e . && $(PY) -m steerlab run --out out/default

test:
	$(PY) -m pip install -e ".[test]" && $(PY) -m pytest -q

# the conformance evaluation (catalogue matrix, random plants): .ci/run's second step
conformance:
	$(PY) -m pytest -q -m conformance

bench:
	$(PY) -m steerlab bench --json

experiment:
	$(PY) -m steerlab experiment zwierzewicz2021 --out out/zwierzewicz2021
