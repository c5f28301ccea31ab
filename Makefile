# The two commands of the README. Both work in a project virtual environment
# (VENV, default .venv) made from SYSTEM_PYTHON, so they run the same on Debian's
# managed Python (which refuses `pip install` outside a venv) and never touch a
# system interpreter. `make test VENV=/path/to/other/venv` reuses another one.
SYSTEM_PYTHON ?= python3
VENV ?= .venv
PYTHON := $(VENV)/bin/python
PIP = $(PYTHON) -m pip install --disable-pip-version-check --quiet

.PHONY: sample test bench validator

$(PYTHON):
	$(SYSTEM_PYTHON) -m venv $(VENV)
	$(PIP) --upgrade pip

# install, compile the numba kernels (so the editor's first uses do not), run the main
# job on the bundled sample
sample: $(PYTHON)
	$(PIP) -e ".[gui]"
	$(PYTHON) -m matshop warm-up --if-cold
	$(PYTHON) -m matshop demo resources/sample --out matshop-demo

# the Khronos glTF validator the export tests use (skipped, with the reason, without npm)
validator:
	@if command -v npm >/dev/null; then \
		npm install --prefix tools --no-audit --no-fund --loglevel=error >/dev/null; \
	else \
		echo "npm not found: the glTF validator tests will be skipped"; \
	fi

# install what the tests need, then lint and run the whole suite (the import-linter
# contract runs inside pytest; Xvfb is used when there is no display; pytest's
# summary lists every skipped test with its reason). Two passes: the tests marked
# `serial` time the GUI thread or the event loop, so they run first with nothing else
# on the cores; then the rest on TEST_WORKERS processes (pytest-xdist), one test file
# per worker at a time so module fixtures are built once. The second pass runs even
# when the first fails, and the recipe fails when either did.
TEST_WORKERS ?= 2
XVFB := $(if $(DISPLAY),,$(if $(shell command -v xvfb-run),xvfb-run -a -s "-screen 0 1280x1024x24"))

test: $(PYTHON) validator
	$(PIP) -e ".[gui,test]"
	$(PYTHON) -m ruff check matshop tests benchmarks scripts
	$(PYTHON) -m matshop warm-up --if-cold
	status=0; \
	$(XVFB) $(PYTHON) -m pytest -m serial || status=$$?; \
	$(XVFB) $(PYTHON) -m pytest -m "not serial" -n $(TEST_WORKERS) --dist loadfile || status=$$?; \
	exit $$status

# every benchmark script, then one table of goal / ratio / verdict (benchmarks/table.py),
# after the same warm-up as the other commands (kernels and bytecode compiled)
bench: $(PYTHON)
	$(PIP) -e ".[gui]"
	$(PYTHON) -m matshop warm-up --if-cold
	$(XVFB) $(PYTHON) benchmarks/table.py
