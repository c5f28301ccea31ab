# The two commands of the README. PYTHON may point at a venv's interpreter.
PYTHON ?= python3
PIP = $(PYTHON) -m pip install --disable-pip-version-check --quiet

.PHONY: sample test bench

# install, then run the main job on the bundled sample
sample:
	$(PIP) -e ".[gui]"
	$(PYTHON) -m matshop demo resources/sample --out matshop-demo

# install what the tests need, then lint and run the whole suite (the import-linter
# contract runs inside pytest; Xvfb is used when there is no display)
test:
	$(PIP) -e ".[gui,test]"
	$(PYTHON) -m ruff check matshop tests benchmarks scripts
	if [ -z "$$DISPLAY" ] && command -v xvfb-run >/dev/null; then \
		xvfb-run -a -s "-screen 0 1280x1024x24" $(PYTHON) -m pytest; \
	else \
		$(PYTHON) -m pytest; \
	fi

bench:
	$(PYTHON) benchmarks/spaces.py
