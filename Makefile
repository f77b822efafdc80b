# Two commands do all the set-up on a fresh machine with Python 3.11 and pip:
#   make demo   - create .venv, install uvms-pin (no extra), run the main scenario into out/demo
#   make test   - create .venv, install uvms-pin with dev tools, lint and run the test suite
#   make check  - while developing: lint and every test but the long ones (marked slow), in a
#                 few minutes on a built checkout
#   make results - regenerate every table (docs/results/*.md) and figure the docs quote
#                  (RESULTS="paper robustness" for some; the list is scripts/make_results.py)
#   make docs    - build the documentation site into site/ (mkdocs.yml), --strict, offline
#   make sanitize - after a C++ change: the core built with AddressSanitizer (build/venv-asan),
#                   the tests that call it: every out-of-bounds or freed access reported
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
BASE_STAMP := $(VENV)/.installed-base
DEMO_SCENARIO ?= scenarios/realistic_force_tracking.toml
DEMO_OUT ?= out/demo

.PHONY: demo test check lint bench results fuzz docs clean browser-install sanitize

SOURCES := pyproject.toml CMakeLists.txt $(wildcard src/uvms_core/*.cpp src/uvms_core/*.hpp)

# pip builds the compiled core (src/uvms_core, CMakeLists.txt) while installing: a changed
# C++ source re-runs the install. The demo needs uvms-pin alone ($(BASE_STAMP)); the tests,
# lint and benchmarks the dev extra ($(STAMP), which includes it).
# The build requirements (pyproject.toml's [build-system] requires, the one list of them, plus
# what scikit-build-core asks for: cmake or ninja when the system has none) go into the venv
# first and pip builds with --no-build-isolation: `pin` (and coal, eigenpy, boost) is installed
# once, not a second time in a throw-away build environment, and a re-install compiles only the
# changed units (the include paths stay those of the venv, the build directory is build/).
# The package's own dependencies (pyproject.toml's, and the extra's: [dev] or none) are
# installed while pip compiles the core, by a second pip beside it: the compile keeps both cores
# busy for minutes, the install is mostly one core unpacking wheels, and the two touch disjoint
# packages (the build requirements are installed first and satisfy the dependencies' pins).
# `pip check` then says whether the environment is whole.
# The package's modules are then compiled to bytecode once (0.3 s), as pip does for a regular
# install and not for an editable one: every `uvms-pin` and test process would otherwise
# compile them again where PYTHONDONTWRITEBYTECODE is set (0.15 s a process start-up).
# The dependencies are installed --no-compile and then compiled to bytecode by compileall,
# their own test suites left out (pandas/tests, scipy's, ...: a fifth of the 12,500 modules,
# which nothing here imports): 16 s of CPU instead of pip's 26 s, taken from the compile of
# the core beside it. The build requirements too, which puts their compile (2 s) after the
# start of the core's build; the compile skips what is already compiled (pip itself).
# A module left uncompiled (a syntax error) is compiled when imported, as pip would leave it.
# One process: with -j 0 the pool's per-file overhead alone took 10 s of CPU on a compiled
# site-packages (0.7 s in one process), and the compile runs beside the core's anyway.
BUILD_REQUIRES := $(VENV)/build-requirements.txt
DEPENDENCIES := $(VENV)/dependencies.txt
define install_core
	$(BIN)/python -c 'import tomllib; print(*tomllib.load(open("pyproject.toml", "rb"))["build-system"]["requires"], sep="\n")' > $(BUILD_REQUIRES)
	$(BIN)/python -m pip install --quiet --no-compile -r $(BUILD_REQUIRES)
	extra=$$($(BIN)/python -c 'from scikit_build_core.build import get_requires_for_build_editable as r; print(*r())'); \
	  [ -z "$$extra" ] || $(BIN)/python -m pip install --quiet --no-compile $$extra
	$(BIN)/python -c 'import sys, tomllib; p = tomllib.load(open("pyproject.toml", "rb"))["project"]; x = sys.argv[1].strip("[]"); print(*p["dependencies"], *(p["optional-dependencies"][x] if x else ()), sep="\n")' '$(1)' > $(DEPENDENCIES)
	site=$$($(BIN)/python -c 'import sysconfig; print(sysconfig.get_path("purelib"))'); \
	  { $(BIN)/python -m pip install --quiet --no-compile -r $(DEPENDENCIES) && \
	    { $(BIN)/python -m compileall -qq -x 'site-packages/.*/tests?/' "$$site" || true; }; } & deps=$$!; \
	  $(BIN)/python -m pip install --quiet --no-build-isolation --no-deps -e . ; built=$$?; \
	  wait $$deps; installed=$$?; [ $$built = 0 ] && [ $$installed = 0 ]
	$(BIN)/python -m pip check
	$(BIN)/python -m compileall -q -j 0 uvms_pin
endef

$(STAMP): $(SOURCES)
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(call install_core,[dev])
	touch $(STAMP) $(BASE_STAMP)

$(BASE_STAMP): $(SOURCES)
	$(PYTHON) -m venv $(VENV)
	$(call install_core,)
	touch $(BASE_STAMP)

demo: $(BASE_STAMP)
	@# --overwrite: the demo reruns into the same directory (only uvms-pin's files are replaced)
	$(BIN)/uvms-pin run $(DEMO_SCENARIO) --out $(DEMO_OUT) --html --overwrite

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/lint-imports

# the replay tests open replay.html in a real headless browser: Debian's chromium, installed
# when it is missing and can be (root with apt-get; otherwise those tests skip). In the
# background, from the start of `make test`, while the venv is made and the core compiles
# (apt is downloads and one core unpacking: about 30 s that the tests no longer wait for
# after the build); the tests wait for it to end. Its output: build/browser-install.log.
# Without the packages chromium recommends (25 packages instead of 115: a printer dialog, avahi,
# udev, perl's web libraries), which a headless browser does not use: 10 s of CPU instead of 16 s
# beside the core's compile.
BROWSER_LOG := build/browser-install.log
BROWSER_PID := build/browser-install.pid
BROWSER_STATUS := build/browser-install.status
browser-install:
	@rm -f $(BROWSER_PID) $(BROWSER_STATUS)
	@command -v chromium >/dev/null 2>&1 || { \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    mkdir -p build; echo "installing Debian's chromium in the background ($(BROWSER_LOG))"; \
	    ( { apt-get update && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends chromium; }; \
	      echo $$? > $(BROWSER_STATUS) ) > $(BROWSER_LOG) 2>&1 < /dev/null & echo $$! > $(BROWSER_PID); \
	  else echo "chromium missing and not installable here (needs root + apt-get): browser tests will skip"; fi; }

test: browser-install $(STAMP) lint
	@if [ -f $(BROWSER_PID) ]; then \
	  pid=$$(cat $(BROWSER_PID)); rm -f $(BROWSER_PID); \
	  kill -0 $$pid 2>/dev/null && echo "waiting for chromium's install to end ($(BROWSER_LOG))"; \
	  while kill -0 $$pid 2>/dev/null; do sleep 1; done; \
	  if [ "$$(cat $(BROWSER_STATUS) 2>/dev/null)" != 0 ]; then tail -n 5 $(BROWSER_LOG); \
	    echo "chromium's install failed ($(BROWSER_LOG)): browser tests will skip"; fi; fi
	@# two workers per two cores (pytest-xdist): each test is independent of the others' order;
	@# whole files to a worker (--dist loadfile: a file's shared run, the doc runs, the bad-input
	@# corpus, is made once, not once per worker), in the order collected: the longest files
	@# first (tests/slow_tests.py), so that no worker ends alone with a long file begun last
	$(BIN)/python -m pytest -q -n auto --dist loadfile --no-loadscope-reorder

# the loop of a change: lint and every test not marked slow (the long physics campaigns, long
# runs, the generated-input tests, the notebooks, the doc runs and the site: `make test` runs
# them; pyproject.toml's markers say what slow is), at most 3 minutes on the 2-core machine
check: $(STAMP) lint
	$(BIN)/python -m pytest -q -n auto --dist loadfile --no-loadscope-reorder -m "not slow"

# the generated-input campaign (tests/fuzz): HYPOTHESIS_PROFILE=campaign draws 6 times the
# inputs `make test` draws, from FUZZ_SEED (printed; FUZZ_SEED=N make fuzz replays or varies
# it), and prints how many inputs each entry point got and how long they took
FUZZ_SEED ?= 20261204
fuzz: $(STAMP)
	@echo "fuzz campaign, seed $(FUZZ_SEED)"
	HYPOTHESIS_PROFILE=campaign $(BIN)/python -m pytest -q tests/fuzz \
	  --hypothesis-seed=$(FUZZ_SEED) --hypothesis-show-statistics

# every benchmarks/bench_*.py, one after the other (ratios only; tables in out/bench/);
# the dev install includes the bench extra (mujoco)
bench: $(STAMP)
	@set -e; for script in benchmarks/bench_*.py; do \
	  echo "== $$script"; $(BIN)/python $$script; done

results: $(STAMP)
	$(BIN)/python scripts/make_results.py $(if $(RESULTS),--only $(RESULTS))

# the site: every page of docs/ in mkdocs.yml's nav, the API reference from the docstrings;
# --strict: a broken link or anchor, a page left out of the nav, an unreadable docstring fail
docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --site-dir site

# the compiled core with AddressSanitizer: a copy of .venv (build/venv-asan: under build/, which
# every tool here leaves alone) whose core is built into build/asan with -fsanitize=address
# (with line numbers, not stripped); the tests of the packages that call the core run there
# with the sanitizer's runtime loaded first (CPython is not built with it; libstdc++ before it,
# or its interceptor of C++ exceptions finds none). A read or write out of bounds or after
# free stops the test with the sanitizer's report (its file in ASAN_LOG_DIR).
# EIGEN_MALLOC_ALREADY_ALIGNED=1: Eigen takes malloc as unaligned under the sanitizer and frees
# with its own aligned scheme what libpinocchio (built without it) allocated with malloc, a
# false report at the first pinocchio::Data the core destroys. Not part of `make test` (about
# 20 minutes on 2 cores: docs/compiled_core.md). The batch's memory-estimate tests skip
# themselves there (the sanitizer's shadow memory is not the batch's).
ASAN_VENV := build/venv-asan
ASAN_LOG_DIR ?= out/asan
ASAN_TESTS ?= tests/physics tests/sim tests/perception tests/ocp tests/control tests/apps/gym
sanitize: $(STAMP)
	rm -rf $(ASAN_VENV) $(ASAN_LOG_DIR) && mkdir -p build $(ASAN_LOG_DIR)
	cp -a $(VENV) $(ASAN_VENV)
	SKBUILD_BUILD_DIR=build/asan SKBUILD_CMAKE_BUILD_TYPE=RelWithDebInfo \
	  SKBUILD_INSTALL_STRIP=false SKBUILD_CMAKE_ARGS="-DCMAKE_CXX_FLAGS=-fsanitize=address \
	  -fno-omit-frame-pointer -DEIGEN_MALLOC_ALREADY_ALIGNED=1;-DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=address" \
	  $(ASAN_VENV)/bin/python -m pip install --quiet --no-build-isolation --no-deps -e .
	LD_PRELOAD="$$(gcc -print-file-name=libasan.so) $$(gcc -print-file-name=libstdc++.so)" \
	  ASAN_OPTIONS=detect_leaks=0:log_path=$(ASAN_LOG_DIR)/asan \
	  $(ASAN_VENV)/bin/python -m pytest -q -n auto --dist loadfile $(ASAN_TESTS); status=$$?; \
	  if ls $(ASAN_LOG_DIR)/asan.* >/dev/null 2>&1; then \
	    echo "AddressSanitizer reports: $(ASAN_LOG_DIR)"; head -n 30 $(ASAN_LOG_DIR)/asan.*; exit 1; fi; \
	  exit $$status

clean:
	rm -rf $(VENV) out build site *.egg-info
