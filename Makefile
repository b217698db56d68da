# winder — the two commands of the README: `make demo` and `make test`.
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV   ?= .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.winder-installed
OUT    ?= out

.PHONY: demo test test-slow bench peers fmu docs-figures lint chromium libtbb clean venv pin-casadi \
	scene-reference readme-numbers docs-numbers docs

# pip compiles every module to bytecode (not --no-compile: where PYTHONDONTWRITEBYTECODE
# is set, as in many containers, every process would then compile what it imports again:
# measured 1.3-1.6x the CPU of each demo step, more than the 25 s pip saves once).
$(STAMP): pyproject.toml
	@echo "creating $(VENV) and installing winder with its dependencies (pip: 1-2 min the first time, silent for up to a minute while it unpacks and compiles)"
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --progress-bar off -e '.[test,fmu,peers]'
	touch $(STAMP)

# The pin_casadi generator (Pinocchio's C++ headers on casadi::SX, winder/model/_pin_casadi.cpp):
# built under ~/.cache/winder/pin-casadi/<pin, casadi, eigen versions>/ (shared by every clone
# and venv; $(VENV)/winder-pin-casadi where the home cache is not writable) when missing
# (about 160 s of g++ and 4 GB, once per version); a no-op otherwise; a warning only where
# g++ is missing. Only the generated code's route "cpp" needs it (WINDER_ROUTE=cpp): the
# default route "py" gives the same expressions without it, so `make demo` never waits for
# it; `make test` builds it for the routes' cross-check (tests/model/test_routes.py).
pin-casadi: $(STAMP)
	$(PY) -m winder.model.pin_casadi

venv: $(STAMP) pin-casadi

# The documentation site (mkdocs.yml; docs/ into site/, warnings as errors): its own venv
# with the `docs` extra of pyproject.toml alone, not winder's dependencies nor the C++
# generator (griffe reads src/ without importing it): 50 s the first time on the loaded
# 2-core machine, then about 10 s for the build alone. Open site/index.html.
DOCS_VENV  ?= .venv-docs
DOCS_STAMP := $(DOCS_VENV)/.winder-docs-installed

$(DOCS_STAMP): pyproject.toml
	$(PYTHON) -m venv $(DOCS_VENV)
	$(PYTHON) -c "import tomllib; print('\\n'.join(tomllib.load(open('pyproject.toml', 'rb'))['project']['optional-dependencies']['docs']))" > $(DOCS_VENV)/requirements-docs.txt
	$(DOCS_VENV)/bin/python -m pip install --quiet --disable-pip-version-check -r $(DOCS_VENV)/requirements-docs.txt
	touch $(DOCS_STAMP)

docs: $(DOCS_STAMP)
	NO_MKDOCS_2_WARNING=1 $(DOCS_VENV)/bin/python -m mkdocs build --strict --quiet --site-dir site
	@echo "documentation site in site/ (open site/index.html)"

# Headless Chromium for the browser test and the snapshots (Debian package; root only).
chromium:
	@if command -v chromium >/dev/null 2>&1; then :; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	  echo "installing chromium for the snapshots (apt-get; about 1 min, once)"; \
	  (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null) \
	    || echo "warning: could not install chromium; browser tests will be skipped"; \
	else echo "warning: chromium not found and not root; browser tests will be skipped"; fi

# TBB for ecospy, the second FMI host of the native FMU's tests (Debian package; root only).
libtbb:
	@if ldconfig -p 2>/dev/null | grep -q 'libtbb.so.12'; then :; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	  echo "installing libtbb12 (apt-get)"; \
	  (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libtbb12 >/dev/null) \
	    || echo "warning: could not install libtbb12; the ecospy host test will be skipped"; \
	else echo "warning: libtbb12 not found and not root; the ecospy host test will be skipped"; fi

# make demo: the first result first (the paper's winding cycle, about 10 s), then the rest in
# five groups, two at a time (-j2: the machine's two cores; the longest first, and no group
# waits for another). BLAS runs one thread per process (two processes already fill the two
# cores; OpenBLAS's second thread made the flexible machine's modes 6x slower on the loaded
# machine); set OPENBLAS_NUM_THREADS to override. Chromium (for the snapshots) is installed
# just before the first snapshots of whichever group gets there first (the others wait on
# its lock), never before a group's simulations. Each group's commands name their scene.
DEMO_GROUPS := demo-flexible demo-control demo-two-drum demo-paper-maps demo-paper
CHROMIUM_READY = @if command -v flock >/dev/null 2>&1; then \
	  flock $(VENV)/.chromium-lock $(MAKE) --no-print-directory chromium; \
	else $(MAKE) --no-print-directory chromium; fi

demo: export OPENBLAS_NUM_THREADS ?= 1
demo: export OMP_NUM_THREADS ?= 1
demo: $(STAMP)
	@echo "demo: the first result, the paper's winding cycle (figures in $(OUT)/plots/)"
	$(PY) -m winder run models/paper_winding.toml --out $(OUT)/paper_winding.csv --plots $(OUT)/plots --progress
	@echo "demo: the other scenes, two at a time (about 4 min; out/ fills as they finish)"
	@$(MAKE) --no-print-directory -j2 $(DEMO_GROUPS)
	@echo "demo outputs in $(OUT)/"

.PHONY: $(DEMO_GROUPS)
demo-paper: $(STAMP)
	$(PY) -m winder run models/paper_winding_no_web.toml --out $(OUT)/paper_winding_no_web.npz --plots $(OUT)/plots --progress
	$(PY) -m winder run models/free_spin.toml --out $(OUT)/free_spin.csv --plots $(OUT)/plots

# the native FMUs (FMI 2.0 and 3.0) and the control examples through them
demo-control: $(STAMP)
	$(PY) -m winder fmu models/paper_winding.toml -o $(OUT)/fmu/paper_winding.fmu
	$(PY) -m winder fmu models/two_drum_winder.toml -o $(OUT)/fmu/two_drum_winder.fmu
	$(PY) -m winder fmu models/winder_line_fmu.toml -o $(OUT)/fmu/winder_line_fmu.fmu
	$(PY) -m winder fmu models/two_drum_winder.toml -o $(OUT)/fmu/two_drum_winder_fmi3.fmu --fmi-version 3
	$(PY) examples/tension_control_fmu.py --fmu $(OUT)/fmu/winder_line_fmu.fmu --out $(OUT)
	$(PY) examples/speed_control_fmu.py --out $(OUT)
	$(PY) examples/tension_loop_design.py --out $(OUT)
	$(PY) examples/tension_mpc.py --out $(OUT)
	$(PY) examples/calibrate_nip.py --out $(OUT)
	$(PY) -m winder fit models/paper_winding.toml --data $(OUT)/calibrate_nip_record.csv --param contact.stiffness --param contact.damping --out $(OUT)/fit.json --plot $(OUT)/plots/fit.png --scene-out $(OUT)/paper_winding_fitted.toml

demo-paper-maps: $(STAMP)
	$(CHROMIUM_READY)
	$(PY) -m winder view $(OUT)/paper_winding.npz --html $(OUT)/paper_winding.html --snapshots $(OUT)/snapshots --every 100
	$(PY) -m winder modes models/paper_winding.toml --plot $(OUT)/plots/resonance_map.png --csv $(OUT)/modes.csv
	$(PY) -m winder sweep models/paper_winding.toml --vary drum.drive.web_speed=10:30:11 --output-step 2e-3 --workers 1 --out $(OUT)/sweep --plot $(OUT)/plots/runnability_map.png

demo-two-drum: $(STAMP)
	$(PY) -m winder run models/two_drum_winder.toml --out $(OUT)/two_drum_winder.npz --plots $(OUT)/plots --progress
	$(PY) -m winder run models/winder_line_dancer.toml --t-end 60 --out $(OUT)/winder_line_dancer.npz --plots $(OUT)/plots --progress
	$(PY) -m winder modes models/winder_line_dancer.toml --roll parent --points 60 --plot $(OUT)/plots/winder_line_dancer_modes.png --csv $(OUT)/winder_line_dancer_modes.csv
	$(CHROMIUM_READY)
	$(PY) -m winder view $(OUT)/winder_line_dancer.npz --html $(OUT)/winder_line_dancer.html --snapshots $(OUT)/snapshots_line_dancer --every 20
	$(PY) -m winder view $(OUT)/two_drum_winder.npz --html $(OUT)/two_drum_winder.html --snapshots $(OUT)/snapshots_two_drum --every 100
	$(PY) -m winder modes models/two_drum_winder.toml --plot $(OUT)/plots/two_drum_modes.png --csv $(OUT)/two_drum_modes.csv
	$(PY) -m winder run models/winder_line.toml --out $(OUT)/winder_line.npz --plots $(OUT)/plots --progress
	$(PY) -m winder view $(OUT)/winder_line.npz --html $(OUT)/winder_line.html --snapshots $(OUT)/snapshots_line --every 100

# the flexible two-drum winder (issue #25): its first 5 s with the deflection, line-load
# and twist figures, the animation, and its modes over the whole cycle's radii (0.05-0.6 m):
# 67 s of CPU with an empty cache (its code's build 13 s of g++, half of it the Jacobian;
# the modes 16 s with one BLAS thread, 80 s with two on the loaded machine)
demo-flexible: $(STAMP)
	$(PY) -m winder run models/two_drum_winder_flexible.toml --out $(OUT)/two_drum_winder_flexible.npz --plots $(OUT)/plots --progress
	$(CHROMIUM_READY)
	$(PY) -m winder view $(OUT)/two_drum_winder_flexible.npz --html $(OUT)/two_drum_winder_flexible.html --snapshots $(OUT)/snapshots_flexible --every 1
	$(PY) -m winder modes models/two_drum_winder_flexible.toml --radius-max 0.6 --points 40 --no-simulate --plot $(OUT)/plots/two_drum_flexible_modes.png --csv $(OUT)/two_drum_flexible_modes.csv

test: $(STAMP) pin-casadi chromium libtbb
	$(PY) -m ruff check src viewer tests examples benchmarks tools
	$(VENV)/bin/lint-imports
	$(PY) -m pytest -q

test-slow: $(STAMP) chromium
	$(PY) -m pytest -q -m slow

# Every machine's library (its generated code and the C integrators of src/winder/solve/c/)
# built with AddressSanitizer and UBSan (WINDER_SANITIZE=1: -O1, its own cache key), and
# the kernel tests run through it: every shipped scene, the located events, the guard, the
# core and the exhausted parent. libstdc++ is preloaded too: without it ASan's __cxa_throw
# interceptor aborts in matplotlib's ft2font. A report aborts the run (exit status != 0).
.PHONY: test-asan
test-asan: $(STAMP) pin-casadi
	WINDER_SANITIZE=1 ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  LD_PRELOAD="$$($${CC:-cc} -print-file-name=libasan.so) $$($${CC:-cc} -print-file-name=libstdc++.so.6)" \
	  $(PY) -m pytest -q -p no:cacheprovider tests/solve/test_c_integrators.py \
	    tests/solve/test_core_events.py tests/solve/test_guard.py tests/solve/test_cint.py

# The fixed physics mutants (tests/mutants/catalogue.toml): every one must be killed.
.PHONY: mutants
mutants: $(STAMP)
	$(PY) tests/mutants/run.py

bench: $(STAMP)
	$(PY) benchmarks/rhs_speed.py
	$(if $(BASELINE),$(PY) benchmarks/compiled_machine.py --baseline $(BASELINE))
	$(PY) benchmarks/work_precision.py
	$(PY) benchmarks/fmu_native.py
	$(PY) benchmarks/cli_speed.py
	$(PY) benchmarks/sweep_scaling.py
	$(PY) benchmarks/flex_speed.py
	$(PY) benchmarks/flex_cycle.py
	$(PY) benchmarks/flex_cycle.py --methods
	$(PY) benchmarks/dop853_cycle.py
	$(PY) benchmarks/cycle_profile.py
	$(if $(BEFORE),$(PY) benchmarks/cost_side_by_side.py --before $(BEFORE))
	$(PY) benchmarks/event_cost.py
	$(PY) benchmarks/fit_speed.py
	$(PY) benchmarks/doc_numbers.py --write

# Side by side with MuJoCo (docs/peers.md, docs/peers.png; about 5 min of CPU time).
peers: $(STAMP)
	$(PY) benchmarks/peers/study.py

# docs/scene-reference.md from the key declarations (parts' KEYS, scene/schema.py, the
# effects' settings); a test fails when stale.
scene-reference: $(STAMP)
	$(PY) -m winder.scene.reference --out docs/scene-reference.md

# Every measured number of the README and the docs pages comes from a script
# (docs/contributing.md, "Numbers"): the demo's numbers into docs/numbers.json (from the
# results in $(OUT)/, each scene run where missing: minutes), printed as a table too; then
# every page's <!-- numbers: NAME --> blocks filled from it, the benchmarks' JSON, the
# scene files and closed forms. tests/test_doc_numbers.py fails while a page disagrees.
# The guide's web-line loops and modes into docs/guide_numbers.json (a minute).
readme-numbers: $(STAMP)
	$(PY) benchmarks/readme_numbers.py --out $(OUT) --json docs/numbers.json
	$(PY) benchmarks/guide_numbers.py --json docs/guide_numbers.json
	$(PY) benchmarks/doc_numbers.py --write

# The fill alone (seconds), after `make bench` or a new block (without --write: a check).
docs-numbers: $(STAMP)
	$(PY) benchmarks/doc_numbers.py --write

# The README's resonance map and the examples' figures of the site's gallery (committed
# under docs/; about 2 min).
docs-figures: $(STAMP)
	$(PY) -m winder modes models/paper_winding.toml --plot docs/resonance_map.png --csv docs/modes.csv
	$(PY) examples/tension_loop_design.py --out docs/examples
	$(PY) examples/tension_mpc.py --out docs/examples
	$(PY) examples/speed_control_fmu.py --out $(OUT) && cp $(OUT)/speed_control_fmu.png docs/examples/
	$(PY) examples/tension_control_fmu.py --out $(OUT) && cp $(OUT)/tension_control_fmu.png docs/examples/

# The FMUs and the closed-loop examples (FMPy host): the drum-speed PI loop, and the winder
# line's tension control through its FMU over a whole parent roll.
fmu: $(STAMP)
	$(PY) -m winder fmu models/paper_winding.toml -o $(OUT)/winder.fmu
	$(PY) examples/speed_control_fmu.py --out $(OUT)
	$(PY) -m winder fmu models/winder_line.toml -o $(OUT)/winder_line.fmu
	$(PY) -m winder fmu models/winder_line_small.toml -o $(OUT)/winder_line_small.fmu
	$(PY) -m winder fmu models/two_drum_winder.toml -o $(OUT)/two_drum_winder.fmu
	$(PY) -m winder fmu models/winder_line_fmu.toml -o $(OUT)/winder_line_fmu.fmu
	$(PY) examples/tension_control_fmu.py --fmu $(OUT)/winder_line_fmu.fmu --out $(OUT)

lint: $(STAMP)
	$(PY) -m ruff check src viewer tests examples benchmarks tools

clean:
	rm -rf $(VENV) $(OUT) build *.egg-info src/*.egg-info $(DOCS_VENV) site
