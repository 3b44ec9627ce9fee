# contact3d: every user-visible step is one target. The first two are the README's.
#   make pipeline [SCENE=paper_brick] [ARGS="--set friction.param=2e4"]
#   make test
SCENE ?= paper_brick
BUILD ?= build
JOBS ?= 2
PY := /usr/bin/python3
BIN := $(BUILD)/contact3d
export FF_LOADPATH := /usr/lib/freefem++
export OPENBLAS_NUM_THREADS ?= 2
# Generated reports go to results/runs/; `PUBLISH=1` regenerates the committed ones in results/ on purpose.
REPORTS := $(if $(PUBLISH),results,results/runs)

.PHONY: deps deps-mpi build build-mpi bench-mpi pipeline test tables crosscheck crosscheck-capblock crosscheck-gasket crosscheck-puck crosscheck-slab figures coulomb-getfem hertz validation bench bench-slab bench-free-plate bench-free-slab bench-matrix-free robustness robustness-coulomb random-bodies ball-sweep stress fuzz sanitize clean

deps:
	@bash scripts/install-deps.sh

build: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release >/dev/null
	@cmake --build $(BUILD) -j $(JOBS)

# The distributed backend (PETSc + MUMPS under Open MPI): build-mpi/contact3d, run as
# `mpirun -np P build-mpi/contact3d solve SCENE` (as root Open MPI also needs
# OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1). Its packages are installed only here.
deps-mpi:
	@bash scripts/install-deps.sh --mpi

build-mpi: deps deps-mpi
	@cmake -S . -B build-mpi -DCMAKE_BUILD_TYPE=Release >/dev/null
	@cmake --build build-mpi -j $(JOBS) --target contact3d-mpi
	@ln -sf contact3d-mpi build-mpi/contact3d

# np = 1 and 2 against the serial CHOLMOD path ($(REPORTS)/distributed.md).
bench-mpi: build-mpi build
	$(PY) pipeline/bench_mpi.py --serial $(BIN) --mpi build-mpi/contact3d --n 16 24 32 40 --out $(REPORTS)/distributed.md

# Geometry -> mesh -> solve -> results/<scene>/ (figures when matplotlib is there).
pipeline: build
	$(PY) pipeline/run_scene.py --bin $(BIN) --scene pipeline/scenes/$(SCENE).toml --out results/runs/$(SCENE) $(if $(ARGS),--args "$(ARGS)")

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) --timeout 900

# Tables 1 and 2 of the paper, on the 5-tet mesh and the gmsh mesh ($(REPORTS)/tables.md).
tables: build
	$(PY) pipeline/tables.py --bin $(BIN) --out $(REPORTS)/tables.md

crosscheck: build
	$(PY) pipeline/crosscheck.py --bin $(BIN) --scene pipeline/scenes/$(SCENE).toml --report $(REPORTS)/crosscheck/$(SCENE).md

# The quarter block on a spherical cap (two materials, symmetry rollers, prescribed displacement, pressure,
# a curved contact face with a gap) against FreeFEM at h = 0.05 ... 0.0175 ($(REPORTS)/crosscheck/capblock_series.md).
# A series, not a gate: on the coarse meshes the tangential forces differ by more than the 5% tolerance
# (the report marks those rows FAIL and shows them converging), so the exit status is ignored here; the
# ctests crosscheck_capblock_* are the gate.
crosscheck-capblock: build
	-$(PY) pipeline/crosscheck.py --bin $(BIN) --scene pipeline/scenes/capblock.toml --mesh-param h=0.05,0.035,0.025,0.0175 --report $(REPORTS)/crosscheck/capblock_series.md

# The gasket held by contact alone (pipeline/scenes/gasket.toml) with Coulomb friction (F = 0.3) against FreeFEM at
# h = 4, 2.5 and 1.5 mm ($(REPORTS)/crosscheck/gasket_series.md). A series, not a gate (as crosscheck-capblock):
# u on Γc differs by more than the 5% tolerance at these h (cell averages against nodal constraints where the
# face sticks) and the report shows it falling with h; ctest crosscheck_gasket_held_by_contact_frictionless gates.
crosscheck-gasket: build
	-$(PY) pipeline/crosscheck.py --bin $(BIN) --scene pipeline/scenes/gasket.toml --mesh-param h=0.004,0.0025,0.0015 --variant coulomb_constant --F 0.3 --report $(REPORTS)/crosscheck/gasket_series.md

# A puck pressed flat with Coulomb friction F = 0.3 (pipeline/scenes/pressed_puck.toml) against FreeFEM at
# h = 12 ... 2.5 mm ($(REPORTS)/crosscheck/puck_series.md; FreeFEM takes about 10 minutes on the finest). A series,
# not a gate: the sole sticks, its displacement is a few µm, and both codes still change it by 10-25% from one
# mesh to the next, so u on Γc differs by more than 5% throughout while the difference falls from h = 5 mm on.
crosscheck-puck: build
	-$(PY) pipeline/crosscheck.py --bin $(BIN) --scene pipeline/scenes/pressed_puck.toml --variant scene --mesh-param h=0.012,0.008,0.005,0.0035,0.0025 --timeout 3000 --report $(REPORTS)/crosscheck/puck_series.md

# The thin slab against FreeFEM at h = 0.05 ... 0.0175, cells of 2h and 1.5h ($(REPORTS)/crosscheck/slab_series*.md).
crosscheck-slab: build
	$(PY) pipeline/slab_crosscheck.py --bin $(BIN) --out $(REPORTS)/crosscheck
	$(PY) pipeline/slab_crosscheck.py --bin $(BIN) --out $(REPORTS)/crosscheck --cell-size 1.5h

# The paper's figures for a run (Fig. 3, 6-11), copied into results/figures with the report.
figures: build
	$(PY) pipeline/run_scene.py --bin $(BIN) --scene pipeline/scenes/$(SCENE).toml --out results/runs/$(SCENE) --figures $(REPORTS)/figures --compare-params 2e4,3e5

# Coulomb friction against GetFEM's contact brick on the paper's brick, n = 4..16 ($(REPORTS)/coulomb_getfem.md).
coulomb-getfem: build
	$(PY) pipeline/getfem_coulomb.py --bin $(BIN) --n 4 8 12 16 --out $(REPORTS)/coulomb_getfem.md

# Hertz validation on a finer mesh than the test's ($(REPORTS)/hertz/: table, JSON, pressure profile figure),
# moved by a displacement and (hertz/pressed/) pressed by a pressure, held by contact alone.
hertz: build
	$(PY) tests/hertz_hemisphere.py $(BIN) . --h-pole 0.005 --cell-size 0.01 --report $(REPORTS)/hertz
	$(PY) tests/hertz_hemisphere.py $(BIN) . --h-pole 0.005 --cell-size 0.01 --top-pressure 1e8 \
		--report $(REPORTS)/hertz/pressed
	$(PY) tests/hertz_hemisphere.py $(BIN) . --h-pole 0.005 --fine 0.12 --cell-size 2h --report $(REPORTS)/hertz/graded
	$(PY) tests/hertz_line_contact.py $(BIN) . --h-line 0.003 0.0015 --report $(REPORTS)/hertz/line/hertz_line.md

# Symmetry plane and rotated foundation at n = 4 and 8 ($(REPORTS)/validation.md).
validation: build
	$(PY) pipeline/validation_report.py --bin $(BIN) --ns 4 8 --out $(REPORTS)/validation.md

bench: build
	$(PY) pipeline/bench.py --bin $(BIN) --out $(REPORTS)/bench

# The thin slab over h = 0.05 ... 0.0175, QP solvers side by side ($(REPORTS)/bench/slab.md).
bench-slab: build
	$(PY) pipeline/bench_slab.py --bin $(BIN) --out $(REPORTS)/bench

# A plate lying free, held by contact alone: the equality-constrained dual over h ($(REPORTS)/bench/free_plate.md).
bench-free-plate: build
	$(PY) pipeline/bench_free_plate.py --bin $(BIN) --out $(REPORTS)/bench

# The slab of bench-slab lying free, held by contact alone ($(REPORTS)/bench/free_slab.md).
bench-free-slab: build
	$(PY) pipeline/bench_free_plate.py --body slab --bin $(BIN) --out $(REPORTS)/bench

# The matrix-free dual (Q never formed) against the dense route on a brick and the slab ($(REPORTS)/bench/matrix_free.md).
bench-matrix-free: build
	$(PY) pipeline/bench_matrix_free.py --bin $(BIN) --out $(REPORTS)/bench

# Bodies x slip-dependent laws x two mesh sizes with default settings ($(REPORTS)/robustness.md).
robustness: build
	$(PY) pipeline/robustness.py --bin $(BIN) --out $(REPORTS)/robustness.md

# The same bodies and laws with Coulomb's bound F·λ_n ($(REPORTS)/robustness_coulomb.md).
robustness-coulomb: build
	$(PY) pipeline/robustness.py --bin $(BIN) --model coulomb --out $(REPORTS)/robustness_coulomb.md

# Random bodies, conditions and laws with default settings, each outcome judged against what its loads
# demand ($(REPORTS)/random_bodies.md; SEEDS="1 80" by default, under a minute).
SEEDS ?= 1 80
random-bodies: build
	$(PY) pipeline/random_bodies.py --bin $(BIN) --seeds $(SEEDS) --out $(REPORTS)/random_bodies.md

# The ball held by contact alone over mesh size, cells, F and a lateral load, one and two BLAS threads
# ($(REPORTS)/ball_sweep.md; about 4 minutes).
ball-sweep: build
	$(PY) pipeline/ball_sweep.py --bin $(BIN) --threads 2 1 --out $(REPORTS)/ball_sweep.md

stress: build
	$(PY) pipeline/stress.py --bin $(BIN) --out $(REPORTS)/stress

# libFuzzer targets for the MSH reader, the scene parser and the Medit reader (FUZZ_SECONDS each).
FUZZ_SECONDS ?= 300
fuzz:
	@bash scripts/install-deps.sh --dev
	bash fuzz/build.sh build-fuzz
	mkdir -p build-fuzz/corpus_msh build-fuzz/corpus_scene build-fuzz/corpus_medit
	build-fuzz/fuzz_msh -max_total_time=$(FUZZ_SECONDS) -timeout=10 build-fuzz/corpus_msh fuzz/corpus/msh
	build-fuzz/fuzz_scene -max_total_time=$(FUZZ_SECONDS) -timeout=10 build-fuzz/corpus_scene fuzz/corpus/scene
	build-fuzz/fuzz_medit -max_total_time=$(FUZZ_SECONDS) -timeout=10 build-fuzz/corpus_medit fuzz/corpus/medit

# Unit tests under AddressSanitizer + UndefinedBehaviorSanitizer.
sanitize: deps
	bash scripts/sanitize.sh

clean:
	rm -rf $(BUILD) results/runs meshes/generated
