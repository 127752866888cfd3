# Front door: `make demo` and `make test` install what is missing, build and run.
# The build itself is CMake (CMakePresets.json); this file only strings the steps together.

PACKAGES := build-essential cmake pkg-config git \
  libeigen3-dev libcgal-dev libvtk9-dev libosmesa6-dev libfftw3-dev \
  libsuitesparse-dev libopenblas0-serial \
  libsqlite3-dev sqlite3 libgtest-dev libtoml11-dev libcli11-dev libbenchmark-dev

PRESET ?= release
BUILD := build/$(PRESET)
ROCKLAB := $(BUILD)/rocklab
DEMO_DIR := build/demo

.PHONY: deps build demo test test-sanitize bench format clean

# Installs only the Debian packages that are missing (a no-op when all are present);
# sudo only when not root.
deps:
	@missing=""; \
	for p in $(PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "make deps: installing$$missing"; \
	  if [ "$$(id -u)" -eq 0 ]; then sudo=""; else sudo="sudo"; fi; \
	  $$sudo apt-get update -q && \
	  DEBIAN_FRONTEND=noninteractive $$sudo apt-get install -y -q --no-install-recommends $$missing; \
	fi

build: deps
	cmake --preset $(PRESET)
	cmake --build --preset $(PRESET)

# The main job: the quick oedometer protocol (a cemented sample formed under stress, then
# loaded) into a fresh notebook, and its figure report.
demo: build
	@mkdir -p $(DEMO_DIR)
	@rm -f $(DEMO_DIR)/lab.sqlite
	$(ROCKLAB) run protocols/oedometer-formed-under-stress-quick.toml --lab $(DEMO_DIR)/lab.sqlite
	$(ROCKLAB) report 1 --lab $(DEMO_DIR)/lab.sqlite --out $(DEMO_DIR)/report
	@echo "open $(DEMO_DIR)/report/index.html"

test: build
	ctest --preset $(PRESET)

# The unit tests under address and undefined-behaviour sanitizers.
test-sanitize: deps
	cmake --preset sanitize
	cmake --build --preset sanitize
	ctest --preset sanitize

bench: build
	$(ROCKLAB) bench --threads 1,2

format:
	git ls-files '*.cpp' '*.hpp' | xargs clang-format -i

clean:
	rm -rf build
