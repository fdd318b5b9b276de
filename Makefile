# One command to set up, one to start the lab, one to test. All are idempotent.
#   make setup   create .venv/ from environment.txt and install course_lib into it
#   make lab     set up, release the assignments into the lab's own exchange (.lab/), then start
#                JupyterLab on the course (prints the URL; no browser needed)
#   make test    set up, lint (ruff, notebooks too), then run the whole test suite (unit tests,
#                notebooks, browser tests)
#   make check   the inner loop (under 2 minutes): set up, lint as make test does, then run the tests
#                that need no grading run, colcon build, browser, hub or notebook run
#   make hub     set up, then run the course's JupyterHub for a class (root; course from
#                `python -m coursehub create-course`, see docs/instructors.md)

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
UV     := $(VENV)/bin/uv
UV_VERSION := 0.13.8
LAB_PORT ?= 8888
PYTEST_ARGS ?=
# Most tests wait on discovery, timers and child processes, so more workers than cores pay off;
# each worker reserves a ROS domain of its own (conftest.py). --dist loadfile keeps a file's
# shared fixtures (a colcon build, a JupyterLab server, a grading run) on one worker, and
# --no-loadscope-reorder hands the files out in the order conftest.py gives (longest first).
TEST_WORKERS ?= 4
# make check's tests wait more than they compute (about 130 CPU-s in 95 s on two cores): two more
# workers overlap more of the waiting.
CHECK_WORKERS ?= 6
# Where ROS 2 comes from: pip (the ros-jazzy-* wheels, default), system (/opt/ros/jazzy, sourced
# first) or conda (an activated RoboStack environment). With system/conda the virtual environment
# sees the installed rclpy and only the non-ROS packages of environment.txt are installed.
ROS ?= pip
ifeq ($(ROS),pip)
VENV_FLAGS :=
REQUIREMENTS := environment.txt
else
VENV_FLAGS := --system-site-packages
REQUIREMENTS := $(VENV)/requirements-without-ros.txt
endif

CHP_VERSION := 5.3.0
# The hub directory: coursehub.course.DEFAULT_HUB_DIR unless HUB_DIR=... is given.
HUB_DIR ?=

.PHONY: setup lab test check browser-deps hub-deps hub clean

RVIZ_JS := course_lib/notebook/rviz/js
RVIZ_BUNDLE := course_lib/notebook/rviz/static/rviz.js
setup: $(VENV)/.setup-done $(RVIZ_BUNDLE)

# The notebook's RViz (course_lib/notebook/rviz): its module and three.js, installed from npm into the
# venv and bundled into one file that the widget sends to the browser over the kernel's comm (no CDN:
# the hub's machines are offline). Without npm the view says how to get it.
$(RVIZ_BUNDLE): $(RVIZ_JS)/rviz.js $(RVIZ_JS)/package.json
	@if command -v npm >/dev/null 2>&1; then \
	  mkdir -p $(VENV)/rviz-js && cp $(RVIZ_JS)/package.json $(VENV)/rviz-js/ && \
	  npm install --silent --no-audit --no-fund --prefix $(VENV)/rviz-js && \
	  NODE_PATH=$(VENV)/rviz-js/node_modules $(VENV)/rviz-js/node_modules/.bin/esbuild $(RVIZ_JS)/rviz.js \
	    --bundle --format=esm --minify --log-level=warning --outfile=$@; \
	else echo "npm is not installed: the notebook's RViz needs Node.js and npm to bundle three.js (apt-get install nodejs npm)"; fi

# jsonschema's optional format checkers (pulled in by jupyter-events' jsonschema[format-nongpl]) are
# imported with jsonschema, so in every process that imports nbformat (nbgrader, nbclient, Jupyter,
# the test workers): rfc3987-syntax compiles ~30 Lark parsers (2-4 CPU-s), and the others (arrow's
# date parser through isoduration, the URI and colour checkers) cost about 0.1 CPU-s more. Only
# jsonschema imports them, and nothing here checks those formats: the overrides leave them out.
OPTIONAL_FORMAT_CHECKERS := rfc3987-syntax isoduration arrow fqdn uri-template webcolors jsonpointer \
                            rfc3986-validator rfc3339-validator
$(VENV)/.setup-done: Makefile environment.txt pyproject.toml course_lib/ros/wheelfix.py course_lib/ros2cli/install.py \
                     course_lib/ros/underlay.py course_lib/robot/install.py course_lib/robot/interface_install.py \
                     $(wildcard course_lib/robot/interfaces/*/* course_lib/robot/interfaces/*/*/* course_lib/robot/robot_sim/* course_lib/robot/robot_sim/*/*)
	@$(PYTHON) -c 'import sys; v = sys.version_info[:2]; ok = (3, 10) <= v <= (3, 13); \
	print("Using Python %d.%d from %s" % (v + (sys.executable,))) if ok else \
	sys.exit("Python %d.%d found, but the ROS 2 Jazzy wheels exist for CPython 3.10-3.13 only. " \
	"Run: make setup PYTHON=python3.12 (or any 3.10-3.13 interpreter)" % v)'
	@if [ "$(ROS)" != pip ] && [ -z "$$ROS_DISTRO" ]; then echo "ROS=$(ROS) needs a sourced ROS 2 Jazzy: \
	run 'source /opt/ros/jazzy/setup.bash' (system) or 'conda activate <robostack env>' (conda) first"; exit 1; fi
	@test -x $(PY) || $(PYTHON) -m venv $(VENV_FLAGS) $(VENV)
	@test -x $(UV) || $(PY) -m pip install --quiet --disable-pip-version-check uv==$(UV_VERSION)
	@if [ "$(ROS)" != pip ]; then grep -v -E '^(ros-jazzy-|colcon-)' environment.txt > $(REQUIREMENTS); fi
	@printf '%s ; sys_platform == "never"\n' $(OPTIONAL_FORMAT_CHECKERS) > $(VENV)/overrides.txt
	$(UV) pip install --quiet --python $(PY) -r $(REQUIREMENTS) --overrides $(VENV)/overrides.txt -e .
	@$(UV) pip uninstall --quiet --python $(PY) $(OPTIONAL_FORMAT_CHECKERS) 2>/dev/null || true  # from a venv made before
	$(PY) -m course_lib repair-wheels
	$(PY) -m course_lib install-ros2
	$(PY) -m course_lib underlay
	$(PY) -m course_lib install-robot
	@touch $@

# JupyterLab refuses to run as root unless told; containers and CI often are root.
ALLOW_ROOT := $(if $(filter 0,$(shell id -u)),--allow-root)

# The server gets the notebook session's ROS variables (Fast DDS set-up for camera frames,
# discovery range, ament index), so JupyterLab's terminals and `!` commands have them too, and the
# venv's local_setup.sh (course_lib/ros/underlay.py): its bin/ first on PATH, so they find its commands
# (`ros2` on the pip install, python, colcon) as in an activated venv, and what colcon needs to
# build message packages. Terminals run $SHELL without -l (a login shell would read /etc/profile,
# which sets PATH anew); bash reads ~/.bashrc and then local_setup.bash again
# (course_lib/notebook/student_lab/terminal.py), in case ~/.bashrc puts pyenv or conda first.
# JUPYTER_CONFIG_PATH: a student's lab shows nbgrader's student side only (course_lib/notebook/student_lab).
# A student alone fetches the assignments in Nbgrader > Assignment List from the lab's own exchange
# (.lab/, git-ignored), where the course's grader releases them, again when their source changed
# (course_lib/notebook/student_lab/exchange.py); `python -m autograder grade-lab` grades what they
# submitted there and releases its feedback for Fetch Feedback (autograder/term/lab_grading.py).
lab: setup
	$(PY) -m autograder release-lab
	@echo "Graded feedback on an assignment: Submit it in Nbgrader > Assignment List, run" \
	  "'python -m autograder grade-lab' in a terminal, then press Fetch Feedback."
	eval "$$($(PY) -m course_lib env)" && . "$(CURDIR)/$(VENV)/local_setup.sh" && \
	JUPYTER_CONFIG_PATH="$(CURDIR)/course_lib/notebook/student_lab$${JUPYTER_CONFIG_PATH:+:$$JUPYTER_CONFIG_PATH}" \
	exec $(VENV)/bin/jupyter lab --no-browser --ip=127.0.0.1 --port=$(LAB_PORT) $(ALLOW_ROOT) \
	  --ServerApp.root_dir="$(CURDIR)" --LabApp.default_url=/lab/tree/notebooks \
	  --ServerApp.terminado_settings="$$($(PY) -m course_lib.notebook.student_lab.terminal)"

# Browser tests need Debian's chromium. Install it when we may (root with apt); otherwise the
# browser tests skip and say why.
browser-deps:
	@if command -v chromium >/dev/null 2>&1; then :; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	  echo "Installing Debian's chromium for the browser tests"; \
	  (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null) \
	    || echo "Could not install chromium: browser tests will be skipped"; \
	else echo "chromium is not installed and this user cannot apt-get it: browser tests will be skipped"; fi

# The hub's proxy (configurable-http-proxy, from npm) goes into the venv, not into the system.
# Students' servers run as their own uids and cannot write __pycache__ into the venv or the
# repository: compiled here once, a server starts in about half the time.
hub-deps: $(VENV)/chp/.installed-$(CHP_VERSION) $(VENV)/.bytecode-done

$(VENV)/chp/.installed-$(CHP_VERSION):
	@if command -v npm >/dev/null 2>&1; then \
	  npm install --silent --no-audit --no-fund --prefix $(VENV)/chp configurable-http-proxy@$(CHP_VERSION) && touch $@; \
	else echo "npm is not installed: the hub needs Node.js and npm for configurable-http-proxy (apt-get install nodejs npm); the hub test will be skipped"; fi

# Bytecode for the hub's users, who cannot write it into the venv; not for what they never run
# (packages' own tests, pip, the browser tests' playwright, pytest): a quarter fewer files.
$(VENV)/.bytecode-done: $(VENV)/.setup-done
	$(PY) -m compileall -q -j 2 -x '/(tests|pip|playwright|_pytest)/' $(VENV)/lib course_lib coursehub autograder > /dev/null || true
	@touch $@

# The course's JupyterHub on http://127.0.0.1:8000 (the port given to create-course).
hub: setup hub-deps
	@if [ "$$(id -u)" != 0 ]; then echo "make hub runs the servers as the students' Linux accounts: run it as root"; exit 1; fi
	$(PY) -m coursehub $(if $(HUB_DIR),--hub-dir $(HUB_DIR)) start

# After the tests, Fast DDS's own tool removes the shared-memory segments of the processes the
# tests killed (each holds up to 32 MB of memory in /dev/shm until removed; `python -m course_lib doctor` counts them).
# The suite starts hundreds of Python processes: with PYTHONDONTWRITEBYTECODE set (some shells and
# CI images set it) each would compile again every module that has no bytecode yet, and each
# xdist worker would rewrite the asserts of every test module (9.4 instead of 4.1 CPU-s to
# collect, per worker), so the suite runs without it.
test: setup browser-deps hub-deps
	$(PY) -m ruff check .
	env -u PYTHONDONTWRITEBYTECODE $(PY) -m pytest -n $(TEST_WORKERS) --dist loadfile --no-loadscope-reorder $(PYTEST_ARGS); status=$$?; \
	PATH="$(VENV)/bin:$$PATH" fastdds shm clean >/dev/null 2>&1; exit $$status

# The tests marked slow (colcon builds, grading runs, lessons' commands), browser or hub are left
# out, and -p no:nbmake leaves out the notebooks (conftest.py then accepts addopts' --nbmake).
CHECK_MARKERS ?= not slow and not browser and not hub
check: setup
	$(PY) -m ruff check .
	env -u PYTHONDONTWRITEBYTECODE $(PY) -m pytest -n $(CHECK_WORKERS) --dist loadfile --no-loadscope-reorder -p no:nbmake -m "$(CHECK_MARKERS)" $(PYTEST_ARGS); status=$$?; \
	PATH="$(VENV)/bin:$$PATH" fastdds shm clean >/dev/null 2>&1; exit $$status

clean:
	rm -rf $(VENV) .pytest_cache artifacts .lab
