# Set-up is part of every target: a fresh machine needs only python3 and make.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: demo test bench clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/bladecase backbone --chain 2 --k 1 --m 0.5 --gap 1 --periods 1:12:600 \
		--json results/backbone_2dof.json --plot results/backbone_2dof.png \
		--table results/backbone_2dof.txt
	$(BIN)/bladecase backbone --chain 2 --k 1 --m 0.5 --gap 1 --periods 3:14.5:24 --ipp 2 --quiet \
		--json results/modes_2ipp_2dof.json --plot results/modes_2ipp_2dof.png \
		--table results/modes_2ipp_2dof.txt

test: $(STAMP)
	$(BIN)/python -m pytest

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_core.py
	$(BIN)/python benchmarks/bench_kipp.py --skip-b
	$(BIN)/python benchmarks/bench_fem.py

clean:
	rm -rf $(VENV) results build *.egg-info
