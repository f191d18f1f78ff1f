# vipvflow: the user-facing commands. Each target calls one documented CLI command;
# every target depends on `setup`, so each works alone on a fresh clone.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
YEAR   ?= 2024
CONF   ?= demo
SCHEDULER ?=
WORKERS ?=
RUN    ?= out/demo/$(YEAR)
DB_DIR ?= data/pg
# Debian packages of the database and browser tests (make system-deps)
SYSTEM_PACKAGES := postgresql-15 postgresql-15-postgis-3 chromium

.PHONY: setup system-deps simulate test bench data app db db-stop clean help
help:
	@echo "make setup                    system-deps, then $(VENV) with vipvflow[test,db,app]"
	@echo "make system-deps              apt-get install $(SYSTEM_PACKAGES) (Debian, root or sudo)"
	@echo "make simulate YEAR=2024 [CONF=demo|luxembourg|my.yaml] [SCHEDULER=tcp://host:8786] [WORKERS=N] [QUIET=1]"
	@echo "make test                     run the test suite"
	@echo "make bench                    run benchmarks/, write benchmarks/results/*.json"
	@echo "make data                     fetch the real datasets of data_manifest.yaml (needs a network)"
	@echo "make app [RUN=out/demo/2024]  start the web app on a finished run"
	@echo "make db / make db-stop        start / stop a local PostgreSQL+PostGIS for mirroring"

setup: $(VENV)/.installed

$(VENV)/.installed: pyproject.toml
	@$(MAKE) --no-print-directory system-deps
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e '.[test,db,app]'
	touch $@

# The database (PostgreSQL 15 + PostGIS 3) and browser (Chromium) tests' system packages:
# installed on Debian as root or with passwordless sudo, else one line saying what to install.
system-deps:
	@sh .ci/system-deps $(SYSTEM_PACKAGES)

simulate: setup
	$(BIN)/vipvflow simulate --config $(CONF) --year $(YEAR) \
		$(if $(SCHEDULER),--scheduler $(SCHEDULER)) $(if $(WORKERS),--workers $(WORKERS)) $(if $(QUIET),--quiet)

test: setup
	$(BIN)/python -m pytest $(PYTEST_ARGS)

bench: setup
	$(BIN)/python -m benchmarks $(BENCH_ARGS)

data: setup
	$(BIN)/vipvflow data fetch --manifest data_manifest.yaml

app: setup
	$(BIN)/vipvflow app $(RUN)

db: setup
	$(BIN)/vipvflow db start --dir $(DB_DIR)

db-stop: setup
	$(BIN)/vipvflow db stop --dir $(DB_DIR)

clean:
	rm -rf out data/demo
