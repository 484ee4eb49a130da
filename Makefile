# Set-up is part of every target: a fresh machine needs only python3 and make.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: demo test bench clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test,video]"
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/bladecase demo --out results/demo

test: $(STAMP)
	$(BIN)/python -m pytest

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_core.py
	$(BIN)/python benchmarks/bench_kipp.py --skip-b
	$(BIN)/python benchmarks/bench_fem.py
	$(BIN)/python benchmarks/bench_demo.py

clean:
	rm -rf $(VENV) results build *.egg-info
