# One command sets up and runs the main job (make demo); one runs the tests (make test).
# Each target (re)builds .venv when it is missing or older than pyproject.toml / requirements.lock.
PYTHON ?= python3
VENV := .venv
STAMP := $(VENV)/.installed
BIN := $(VENV)/bin

.PHONY: demo test bench clean-venv

$(STAMP): pyproject.toml requirements.lock
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -c requirements.lock -e '.[test]'
	@touch $(STAMP)

demo: $(STAMP)
	$(BIN)/sidbench demo --out out

# Both cores: each test file on one worker (its module fixtures made once), files shared out.
test: $(STAMP)
	$(BIN)/python -m pytest -q -n auto --dist loadfile

bench: $(STAMP)
	$(BIN)/sidbench bench

clean-venv:
	rm -rf $(VENV)
