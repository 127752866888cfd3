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

.PHONY: deps build demo test test-sanitize bench catalogue references gallery format clean

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

# What the quick protocols give: each run into one notebook (build/catalogue/lab.sqlite) and
# its report (build/catalogue/<protocol>/index.html). About a quarter of an hour on 2 cores.
CATALOGUE_DIR := build/catalogue
catalogue: build
	@mkdir -p $(CATALOGUE_DIR)
	@rm -rf $(CATALOGUE_DIR)/lab.sqlite*
	@n=0; for p in protocols/*-quick.toml; do \
	  n=$$((n + 1)); name=$$(basename $$p .toml); \
	  $(ROCKLAB) run $$p --lab $(CATALOGUE_DIR)/lab.sqlite --quiet && \
	  $(ROCKLAB) report $$n --lab $(CATALOGUE_DIR)/lab.sqlite --out $(CATALOGUE_DIR)/$$name; \
	done
	@echo "catalogue: $(CATALOGUE_DIR)/*/index.html"

# The regression references of the quick protocols (tests/reference, checked by the e2e tests):
# each protocol at three seeds; the value at its own seed, the tolerance from their spread.
# An explicit step: review `git diff tests/reference` before committing.
references: build
	$(ROCKLAB) regress update protocols/*-quick.toml --out tests/reference \
	  --lab build/references.sqlite --seeds 3

# The accuracy gallery (reports/gallery, shown in the README): one cost-accuracy study per rig,
# each a ladder of one numerical setting, finest first. `make -j2 gallery` runs two at once.
GALLERY_DIR := build/gallery
STUDY = $(ROCKLAB) study accuracy --threads 1 --quiet --lab $(GALLERY_DIR)/lab-$@.sqlite \
  --out $(GALLERY_DIR)/$@
GALLERY := oedometer biaxial envelope hydrostatic permeameter ultrasonic
.PHONY: $(GALLERY)
gallery: $(GALLERY)
	@echo "gallery: reports/gallery/{$(shell echo $(GALLERY) | tr ' ' ,)}.png"
define gallery_png
	@mkdir -p reports/gallery
	cp $(GALLERY_DIR)/$@/cost-accuracy.png reports/gallery/$@.png
endef
oedometer: build
	$(STUDY) protocols/oedometer-formed-under-stress-quick.toml \
	  --vary numerics.timestep_safety=0.25,0.5,0.8
	$(gallery_png)
biaxial: build
	$(STUDY) protocols/biaxial-ucs-quick.toml --vary loading.axial_strain_rate_per_s=2.5,5,10,20
	$(gallery_png)
envelope: build
	$(STUDY) protocols/triaxial-envelope-quick.toml \
	  --vary loading.axial_strain_rate_per_s=5,10,20
	$(gallery_png)
hydrostatic: build
	$(STUDY) protocols/hydrostatic-quick.toml --vary sample.count=4000,2000,1000,500
	$(gallery_png)
permeameter: build
	$(STUDY) protocols/permeameter-hydrostatic-3d-quick.toml --vary sample.count=3000,1500,700
	$(gallery_png)
ultrasonic: build
	$(STUDY) protocols/ultrasonic-hydrostatic-quick.toml --vary numerics.timestep_safety=0.25,0.5,0.8
	$(gallery_png)

format:
	git ls-files '*.cpp' '*.hpp' | xargs clang-format -i

clean:
	rm -rf build
