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
# Citus for `make db CITUS_WORKERS=N` and the Citus tests (make citus): the installed one, else
# built from CITUS_SOURCE (a citus-*.tar.gz or a folder of them; by default ../shared/vendor/citus
# when it is beside the clone) with these Debian packages, as root
CITUS_SOURCE ?= $(wildcard ../shared/vendor/citus)
CITUS_BUILD_PACKAGES := postgresql-server-dev-15 liblz4-dev libzstd-dev libkrb5-dev libssl-dev \
	libselinux1-dev libxslt1-dev libpam0g-dev libreadline-dev
CITUS_WORKERS ?=

.PHONY: setup system-deps citus simulate test bench data app db db-stop clean help
help:
	@echo "make setup                    system-deps, then $(VENV) with vipvflow[test,db,app]"
	@echo "make system-deps              apt-get install $(SYSTEM_PACKAGES) (Debian, root or sudo)"
	@echo "make citus [CITUS_SOURCE=citus-13.x.tar.gz]  the installed Citus, else build and install it (root)"
	@echo "make simulate YEAR=2024 [CONF=demo|luxembourg|my.yaml] [SCHEDULER=tcp://host:8786] [WORKERS=N] [QUIET=1]"
	@echo "make test                     run the test suite"
	@echo "make bench                    run benchmarks/, write benchmarks/results/*.json"
	@echo "make data                     fetch the real datasets of data_manifest.yaml (needs a network)"
	@echo "make app [RUN=out/demo/2024]  start the web app on a finished run"
	@echo "make db [CITUS_WORKERS=N] / make db-stop   start / stop a local PostgreSQL+PostGIS (or Citus cluster) for mirroring"

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

# Never part of setup: a build (about a minute on 2 cores, then cached) runs on `make citus` and
# `make test` only, not on `make simulate`. Without Citus and without a source it says in one
# line how to get it, and the Citus tests skip naming it.
citus: setup
	@$(if $(CITUS_SOURCE),$(BIN)/vipvflow db citus >/dev/null 2>&1 || sh .ci/system-deps $(CITUS_BUILD_PACKAGES);) \
	$(BIN)/vipvflow db citus $(if $(CITUS_SOURCE),--source $(CITUS_SOURCE)) || true

simulate: setup
	$(BIN)/vipvflow simulate --config $(CONF) --year $(YEAR) \
		$(if $(SCHEDULER),--scheduler $(SCHEDULER)) $(if $(WORKERS),--workers $(WORKERS)) $(if $(QUIET),--quiet)

test: setup citus
	$(BIN)/python -m pytest $(PYTEST_ARGS)

bench: setup
	$(BIN)/python -m benchmarks $(BENCH_ARGS)

data: setup
	$(BIN)/vipvflow data fetch --manifest data_manifest.yaml

app: setup
	$(BIN)/vipvflow app $(RUN)

db: setup
	$(BIN)/vipvflow db start --dir $(DB_DIR) $(if $(CITUS_WORKERS),--citus-workers $(CITUS_WORKERS))

db-stop: setup
	$(BIN)/vipvflow db stop --dir $(DB_DIR)

clean:
	rm -rf out data/demo
