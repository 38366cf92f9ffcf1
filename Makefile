# Two commands on a fresh machine: `make demo` and `make test`. Both install first.
PYTHON ?= python3.11
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: install demo test bench lint clean

install: $(STAMP)

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test,dask,view,ros,remote,station]"
	touch $(STAMP)

# The main job on the bundled DRC ladder: plan the climb, verify it kinematically, then
# play it in MuJoCo through the robot's own control code (mixed position/PWM arms), closed
# loop through the motion layer. Seed 4 is one of the seeds whose whole climb climbs closed
# loop (docs/results.md gives the rate over seeds).
# validate-plan also writes the run's 3D recording, demo-out/drc.rrd, at 2 poses a second
# to keep the demo's output under 50 MB (docs/viewer.md).
# validate-plan's verdict (exit 1: did not climb) is reported, not treated as a broken
# demo; bad input (exit 2) or a crash still fails it.
demo: install
	mkdir -p demo-out
	$(BIN)/python -m ladders show drc --out demo-out
	$(BIN)/plan-ladder drc --seed 4 -o demo-out/drc.traj.gz --plots demo-out/stances
	$(BIN)/check-plan demo-out/drc.traj.gz --ladder drc
	MUJOCO_GL=egl $(BIN)/validate-plan demo-out/drc.traj.gz --strategy mixed \
		--json demo-out/drc.result.json --plots demo-out/plots \
		--record demo-out/drc.rrd --record-hz 2; \
		status=$$?; [ $$status -le 1 ] || exit $$status; \
		echo "validate-plan verdict written to demo-out/drc.result.json (exit $$status)"

# One pytest worker per core (pytest-xdist); a test file's tests share a worker, so its
# module fixtures (a planned reach, a simulated climb) are built once.
test: install
	MUJOCO_GL=egl $(BIN)/python -m pytest -q -n auto --dist loadfile

bench: install
	$(BIN)/python -m bench

lint: install
	$(BIN)/ruff check .

clean:
	rm -rf $(VENV) demo-out .pytest_cache
