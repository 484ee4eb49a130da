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
	@# optional CHOLMOD from cvxopt's wheel (pip alone): faster, leaner sparse factorisation; SuperLU without it
	$(BIN)/python -m pip install --quiet --only-binary=cvxopt -e ".[cvxopt]" \
	    || echo "optional cvxopt (CHOLMOD) not installed: no wheel for this platform, SuperLU used"
	@# optional METIS ordering for CHOLMOD (pymetis's wheel): less fill on large models; CHOLMOD's AMD without it
	$(BIN)/python -m pip install --quiet --only-binary=pymetis -e ".[metis]" \
	    || echo "optional pymetis (METIS ordering) not installed: no wheel for this platform, AMD used"
	@# optional CHOLMOD (faster sparse factorisation): only where SuiteSparse's headers are installed
	@if [ -f /usr/include/suitesparse/cholmod.h ]; then \
	    $(BIN)/python -m pip install --quiet "scikit-sparse<0.5" \
	    || echo "optional scikit-sparse (CHOLMOD) not installed: SuperLU used"; \
	else echo "optional CHOLMOD: no SuiteSparse headers (apt install libsuitesparse-dev): SuperLU used"; fi
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/bladecase demo --out results/demo

# one worker per core, each test file on one worker (its module fixtures computed once), the slowest files first
# (tests/conftest.py); bytecode caches written even where PYTHONDONTWRITEBYTECODE is set: without them every
# worker rewrites and compiles all the test modules again before its first test (about 4 s of 7 s of collection)
test: $(STAMP)
	PYTHONDONTWRITEBYTECODE= $(BIN)/python -m pytest -n auto --dist loadfile

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_core.py
	$(BIN)/python benchmarks/bench_kipp.py --skip-b
	$(BIN)/python benchmarks/bench_fem.py
	$(BIN)/python benchmarks/bench_demo.py
	$(BIN)/python benchmarks/bench_search.py --cases chain10,chain20,chain50,demo8
	$(BIN)/python benchmarks/bench_search_contact.py --cases cb58w
	$(BIN)/python benchmarks/bench_scaling.py
	$(BIN)/python benchmarks/bench_fe_pipeline.py --skip-110k
	$(BIN)/python benchmarks/bench_solvers.py --skip-110k
	$(BIN)/python benchmarks/bench_ccx.py
	$(BIN)/python benchmarks/bench_reference.py
	$(BIN)/python benchmarks/bench_executor.py
	$(BIN)/python benchmarks/bench_simulate.py
	$(BIN)/python benchmarks/bench_rub.py
	$(BIN)/python benchmarks/bench_nodal_modes.py

clean:
	rm -rf $(VENV) results build *.egg-info
