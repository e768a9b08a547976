# Build, test and example targets. Outputs go to build/ (git-ignored).
#
#   make test      every test program in every configuration of the matrix below, then one
#                  line "N passed, N failed" (test cases summed over the matrix)
#   make examples  the example programs, into build/examples/
#   make bench     the speed/accuracy trade, stability and kernel throughput, written to
#                  bench/results/ (about 12 minutes: 672 s on the Zen 5 of 2026-12-02, before
#                  the race part, which adds 92 s on the loaded Intel Xeon of README)
#   make bench-quick  the same at the smallest sizes (about a minute: 58 s), to build/bench-quick/
#   make clean     remove build/
#
# The matrix: gcc -std=c99, g++ (the same test sources compiled as C++) and clang -std=c99,
# each in double and in float; gcc with -fopenmp run with OMP_NUM_THREADS=2; gcc under
# AddressSanitizer + UndefinedBehaviorSanitizer. All with -Wall -Wextra -pedantic -Werror.
# Compiling the headers dominates the time of `make test` (about 4 to 6 s per program and
# configuration), so: gcc in double and the OpenMP build compile at -O2 (the optimiser's
# warnings, the speed the library ships at), the other configurations at -O1 (the same
# warnings and assertions, about 40 % less compile time); the full-size convergence studies
# run with gcc (double, float), while the sanitizer build runs every assertion on the
# reduced sizes of TEST_QUICK (tests/test.h); g++ and clang (double, float) build one
# program per header plus the compile-only programs (each header alone and
# all three together compile in every configuration); the OpenMP build runs, on the reduced
# sizes, the programs with the three headers' thread-count determinism tests; the sanitizer build skips the two
# compile-only programs (their code is the same headers the other programs exercise) and
# keeps line tables only (-g1: its reports still name file and line; full -g tripled the
# sanitizer build's compile time, 45 s for test_frames alone) at -Og (test_frames: 12 s to
# compile and 34 s to run, against 23 s and 35 s at -O1, 8.5 s and 73 s at -O0); test_compile_all (the three
# headers in one translation unit) runs in gcc double, g++ double and clang float, and
# test_compile_static (the same with *_STATIC) in gcc float, g++ float and clang double.
# Each PASS line in build/<configuration>/<program>.log gives the case's CPU time.
# tests/test_examples.sh runs the example programs with bad arguments, a missing output
# directory and a full standard output (about 3 s); its cases count in the same total.

# Two jobs a core: compiling dominates and the jobs share the cores with whatever else runs;
# with the second core busy (`yes > /dev/null`) nproc jobs got about 1.33 of the 2 cores
# and make test took 10.2 min (6.0 min on idle cores), twice nproc gets about 1.6.
JOBS ?= $(shell echo $$(( $$(nproc 2>/dev/null || echo 1) * 2 )))
WARN := -Wall -Wextra -pedantic -Werror
HEADERS := $(wildcard tensormass.h heml.h frames.h) examples/tetmesh.h tests/test.h tests/compile_all.h \
           tests/fixtures.h
FLOAT := -DTMASS_REAL=float -DHEML_REAL=float -DFRM_REAL=float

# The sanitizer build first: its programs take longest to build and run (test_frames: 22 s
# and 44 s of CPU), so they start first instead of running alone at the end.
CONFIGS := asan-double gcc-double gcc-float gxx-double gxx-float clang-double clang-float omp-double

# gcc builds for this machine (-march=native): the headers' vector paths (intrinsics and
# vector extensions behind compile-time checks of the target, issues 15 and 21) exist only
# when the target has them, so gcc double, gcc float and the OpenMP build run them (heml's
# test_vector_paths_match_scalar compares them with the scalar path bit for bit; the
# OpenMP build's thread-count determinism and allocation tests run them with 2 threads),
# while g++, clang and the sanitizer build (generic x86-64) run the portable scalar code.
# ISO C mode keeps -ffp-contract=off: no fused multiply-adds appear from -march alone.
CC_gcc-double   := gcc -std=c99 -O2 -march=native
CC_gcc-float    := gcc -std=c99 -O1 -march=native $(FLOAT)
CC_gxx-double   := g++ -std=c++11 -O1 -x c++ -DTEST_QUICK
CC_gxx-float    := g++ -std=c++11 -O1 -x c++ $(FLOAT) -DTEST_QUICK
CC_clang-double := clang -std=c99 -O1 -DTEST_QUICK
CC_clang-float  := clang -std=c99 -O1 $(FLOAT) -DTEST_QUICK
CC_omp-double   := gcc -std=c99 -O2 -march=native -fopenmp -DTEST_QUICK
CC_asan-double  := gcc -std=c99 -Og -g1 -fno-omit-frame-pointer -fsanitize=address,undefined \
                   -fno-sanitize-recover=all -DTEST_QUICK

# Passive waiting: libgomp's idle threads otherwise spin (about 300,000 polls, 0.1 to 1 ms)
# at every barrier before they sleep. On a machine whose other core is busy the spinning
# thread takes the time slice of the one it waits for: one test case took 0.25 s on 1
# thread, 141 s on 2, 1.3 s on 2 passive (issue 18), and `make test` 37 minutes instead of
# 4. Passive: idle threads sleep at once; the tests check results, not speed.
ENV_omp-double := OMP_NUM_THREADS=2 OMP_WAIT_POLICY=passive

TESTS := $(basename $(notdir $(wildcard tests/test_*.c)))
COMPILE_ONLY := test_compile_all test_compile_static
# the programs each configuration builds and runs (all of them unless listed here)
$(foreach c,$(CONFIGS),$(eval TESTS_$(c) := $(TESTS)))
TESTS_omp-double := test_frames test_heml test_heml_sim test_tensormass
# the sanitizer build leaves out the two compile-only programs and the tensor-mass
# accuracy studies (their code is test_tensormass's under the sanitizers, at other sizes)
TESTS_asan-double := $(filter-out $(COMPILE_ONLY) test_tensormass_accuracy,$(TESTS))
# each compile-only program in configurations that together cover C and C++, gcc and
# clang, double and float: test_compile_all in g++ double and clang float, test_compile_static
# in gcc float, g++ float and clang double (every header also compiles alone in every
# configuration: as part of its own test programs, or by header_alone below)
TESTS_gcc-float := $(filter-out test_compile_all,$(TESTS))
TESTS_gcc-double := $(filter-out $(COMPILE_ONLY),$(TESTS))
# g++ double and clang float build and run one program per header (each header alone,
# with its implementation) and a compile program; g++ float and clang double build the
# compile program and check that each header alone, with its implementation, compiles
# (header_alone: -fsyntax-only, no code generated, about 1 s a header); every assertion
# runs under gcc (double, float) and the sanitizers
# (compiling a program costs about 4 s of CPU per configuration: the whole matrix of every
# program took make test to 8 minutes on two idle cores after issues 13-16 and 21)
PER_HEADER := test_tensormass_qs test_heml_time test_frames_chain
TESTS_gxx-double := $(PER_HEADER) test_compile_all
TESTS_gxx-float := test_compile_static
TESTS_clang-double := test_compile_static
TESTS_clang-float := $(PER_HEADER) test_compile_all
EXAMPLES := $(basename $(notdir $(wildcard examples/*.c)))
# the examples' argument and write-error behaviour (tests/test_examples.sh), counted like a
# test program of a configuration named "examples"
# tests/test_packaging.sh (CMake and pkg-config consumers) and tests/test_viewer.sh (the
# viewer headless under Xvfb) count the same way; each skips with one line and RESULT 0 0
# when its tools are absent.
ALONE_CONFIGS := gxx-float clang-double
RESULTS := $(foreach c,$(CONFIGS),$(foreach t,$(TESTS_$(c)),build/$(c)/$(t).result)) \
           $(foreach c,$(ALONE_CONFIGS),build/$(c)/header_alone.result) \
           build/examples/test_examples.result build/packaging/test_packaging.result \
           build/viewer/test_viewer.result build/cuda/test_cuda.result

.PHONY: all test test-run examples viewer bench bench-quick clean
# keep the test binaries between runs (they are intermediate files of the .result rules)
.SECONDARY:
all: test

test:
	@rm -f $(RESULTS)
	@$(MAKE) --no-print-directory -k -j$(JOBS) test-run examples; true
	@sh tests/summarize.sh "$(RESULTS)"

test-run: $(RESULTS)

# One compile rule and one run rule per configuration. A run never fails the make: its
# RESULT line (or its absence, for a crash) is read by tests/summarize.sh.
define CONFIG_RULES
build/$(1)/%: tests/%.c $(HEADERS)
	@mkdir -p build/$(1)
	$$(CC_$(1)) $(WARN) -o $$@ $$< -lm

build/$(1)/%.result: build/$(1)/%
	@mkdir -p build/tmp/$(1)
	@TEST_TMPDIR=build/tmp/$(1) $$(ENV_$(1)) ./$$< > build/$(1)/$$*.log 2>&1; \
	  echo "$$$$?" > build/$(1)/$$*.status; \
	  grep '^RESULT ' build/$(1)/$$*.log > $$@ || echo "RESULT 0 1 crashed" > $$@
endef
$(foreach c,$(CONFIGS),$(eval $(call CONFIG_RULES,$(c))))

# Each model header alone with its implementation, syntax and warnings of the front end
# only (one case per header; its errors in build/<configuration>/header_alone.log).
define ALONE_RULE
build/$(1)/header_alone.result: $(HEADERS)
	@mkdir -p build/$(1)
	@rm -f build/$(1)/header_alone.log; pass=0; fail=0; \
	for h in tensormass:TENSORMASS heml:HEML frames:FRAMES; do \
	  if printf '#define %s_IMPLEMENTATION\n#include "%s.h"\n' $$$${h##*:} $$$${h%%:*} | \
	     $$(CC_$(1)) $(WARN) -fsyntax-only -I. -x $(if $(findstring gxx,$(1)),c++,c) - \
	     >> build/$(1)/header_alone.log 2>&1; \
	  then pass=$$$$((pass + 1)); else fail=$$$$((fail + 1)); echo "FAIL $$$${h%%:*}.h alone" >> build/$(1)/header_alone.log; fi; \
	done; echo "RESULT $$$$pass $$$$fail" > $$@; \
	if [ $$$$fail -eq 0 ]; then echo 0; else echo 1; fi > build/$(1)/header_alone.status
endef
$(foreach c,$(ALONE_CONFIGS),$(eval $(call ALONE_RULE,$(c))))

examples: $(foreach e,$(EXAMPLES),build/examples/$(e))

# -O1: the examples run briefly in tests/test_examples.sh (bad arguments, write errors);
# about 40 % less compile time than -O2 (59 s of CPU for the eight)
build/examples/%: examples/%.c $(HEADERS)
	@mkdir -p build/examples
	gcc -std=c99 -O1 $(WARN) -o $@ $< -lm

build/examples/test_examples.result: tests/test_examples.sh $(foreach e,$(EXAMPLES),build/examples/$(e))
	@rm -rf build/tmp/examples
	@sh tests/test_examples.sh build/examples build/tmp/examples > build/examples/test_examples.log 2>&1; \
	  echo "$$?" > build/examples/test_examples.status; \
	  grep '^RESULT ' build/examples/test_examples.log > $@ || echo "RESULT 0 1 crashed" > $@

build/packaging/test_packaging.result: tests/test_packaging.sh tests/consumer/CMakeLists.txt \
    tests/consumer/main.c CMakeLists.txt cmake/softbodyConfig.cmake.in cmake/softbody.pc.in $(HEADERS)
	@mkdir -p build/packaging
	@sh tests/test_packaging.sh build/tmp/packaging > build/packaging/test_packaging.log 2>&1; \
	  echo "$$?" > build/packaging/test_packaging.status; \
	  grep '^RESULT ' build/packaging/test_packaging.log > $@ || echo "RESULT 0 1 crashed" > $@

# The CUDA companion (issue 16): tests/test_cuda.sh compiles frames_cuda.cu with nvcc (sm_80
# and sm_90 in one invocation, warnings as errors) when nvcc is found, and runs the GPU tests
# (tests/cuda_frames.c) when a GPU is present; one skip line otherwise.
build/cuda/test_cuda.result: tests/test_cuda.sh frames_cuda.cu frames_cuda.h tests/cuda_frames.c $(HEADERS)
	@mkdir -p build/cuda
	@sh tests/test_cuda.sh build/tmp/cuda > build/cuda/test_cuda.log 2>&1; \
	  echo "$$?" > build/cuda/test_cuda.status; \
	  grep '^RESULT ' build/cuda/test_cuda.log > $@ || echo "RESULT 0 1 crashed" > $@

# The viewer (examples/viewer/, issue 17): GLFW and OpenGL 3.3 core, built when pkg-config
# finds glfw3 (Debian: libglfw3-dev, libgl-dev), otherwise one line and success. sim.c (the
# three headers) is compiled twice, double and float, so precision switches live; -O1 keeps
# the build of the headers short (about 8 s of CPU; the models still step at interactive
# rates on the built-in scenes).
VIEWER_SRC := $(wildcard examples/viewer/*.c)
VIEWER_DEPS := $(wildcard examples/viewer/*.h) examples/tetmesh.h $(HEADERS)
VIEWER_OBJS := $(patsubst examples/viewer/%.c,build/viewer/%.o,$(filter-out examples/viewer/sim.c,$(VIEWER_SRC))) \
               build/viewer/sim_double.o build/viewer/sim_float.o
VIEWER_CC := gcc -std=c99 -O1 $(WARN)
HAVE_GLFW := $(shell pkg-config --exists glfw3 2>/dev/null && echo yes)

ifeq ($(HAVE_GLFW),yes)
VIEWER_BIN := build/viewer/viewer
viewer: $(VIEWER_BIN)
else
VIEWER_BIN :=
viewer:
	@echo "viewer: skipped (pkg-config cannot find glfw3; on Debian: apt-get install libglfw3-dev libgl-dev)"
endif

# the viewer headless under Xvfb (tests/test_viewer.sh; skipped with a line without GLFW or
# xvfb-run)
build/viewer/test_viewer.result: tests/test_viewer.sh tests/png_check.c $(VIEWER_BIN)
	@mkdir -p build/viewer
	@sh tests/test_viewer.sh build/viewer/viewer build/tmp/viewer > build/viewer/test_viewer.log 2>&1; \
	  echo "$$?" > build/viewer/test_viewer.status; \
	  grep '^RESULT ' build/viewer/test_viewer.log > $@ || echo "RESULT 0 1 crashed" > $@

build/viewer/sim_double.o: examples/viewer/sim.c $(VIEWER_DEPS)
	@mkdir -p build/viewer
	$(VIEWER_CC) -c -o $@ $<

build/viewer/sim_float.o: examples/viewer/sim.c $(VIEWER_DEPS)
	@mkdir -p build/viewer
	$(VIEWER_CC) -DVW_FLOAT -c -o $@ $<

build/viewer/%.o: examples/viewer/%.c $(VIEWER_DEPS)
	@mkdir -p build/viewer
	$(VIEWER_CC) $(shell pkg-config --cflags glfw3 2>/dev/null) -c -o $@ $<

build/viewer/viewer: $(VIEWER_OBJS)
	$(VIEWER_CC) -o $@ $(VIEWER_OBJS) $(shell pkg-config --libs glfw3 2>/dev/null) -lm

# The bench: bench.c plus every adapter bench/model_*.c compiled twice (double, float).
# Built for this machine; the flags and git revision go into every CSV row.
BENCH_CFLAGS := -std=c99 -O3 -march=native -ffp-contract=fast -fopenmp
BENCH_MODELS := $(basename $(notdir $(wildcard bench/model_*.c)))
BENCH_OBJS := $(foreach m,$(BENCH_MODELS),build/bench/$(m)_double.o build/bench/$(m)_float.o)
BENCH_GIT := $(shell git rev-parse --short HEAD 2>/dev/null || echo unknown)$(shell git diff --quiet HEAD -- . ':!bench/results' 2>/dev/null || echo -dirty)
BENCH_DEFS := -DBENCH_FLAGS='"$(BENCH_CFLAGS)"' -DBENCH_GIT='"$(BENCH_GIT)"'

build/bench/%_double.o: bench/%.c bench/bench.h bench/body_mesh.h bench/model_common.h $(HEADERS)
	@mkdir -p build/bench
	gcc $(BENCH_CFLAGS) $(WARN) -c -o $@ $<

build/bench/%_float.o: bench/%.c bench/bench.h bench/body_mesh.h bench/model_common.h $(HEADERS)
	@mkdir -p build/bench
	gcc $(BENCH_CFLAGS) $(WARN) -DBENCH_FLOAT -c -o $@ $<

# The peer (issue 21): Bullet's deformable bodies, when Debian's libbullet-dev is installed
# (pkg-config bullet); otherwise the bench prints how to install it and skips those rows.
# (-Wno-maybe-uninitialized: gcc 12 warns inside Bullet's own array templates.)
BULLET := $(shell pkg-config --exists bullet 2>/dev/null && echo 1)
ifeq ($(BULLET),1)
BENCH_PEER_OBJS := build/bench/peer_bullet.o
BENCH_PEER_DEFS := -DBENCH_HAVE_BULLET
BENCH_PEER_LIBS := $(shell pkg-config --libs bullet) -lstdc++
endif

build/bench/peer_bullet.o: bench/peer_bullet.cpp bench/bench.h bench/body_mesh.h examples/tetmesh.h
	@mkdir -p build/bench
	g++ -std=c++11 -O3 -march=native -Wall -Wextra -Werror -Wno-maybe-uninitialized $(patsubst -I%,-isystem %,$(shell pkg-config --cflags bullet)) -c -o $@ $<

build/bench/bench: bench/bench.c bench/bench.h bench/svg.h $(BENCH_OBJS) $(BENCH_PEER_OBJS)
	gcc $(BENCH_CFLAGS) $(WARN) $(BENCH_DEFS) $(BENCH_PEER_DEFS) -o $@ bench/bench.c $(BENCH_OBJS) $(BENCH_PEER_OBJS) \
	  $(BENCH_PEER_LIBS) -lm

# The bench's 2-thread kernel rows run with passive waiting too (see ENV_omp-double): on a
# shared machine spinning threads measure the neighbours' load, not the kernel. It costs
# the 2-thread rows a wake-up (a few microseconds) per parallel loop; the 1-thread rows and
# the trade and stability parts run on one thread and do not see it.
BENCH_ENV := OMP_WAIT_POLICY=passive

bench: build/bench/bench
	@mkdir -p bench/results
	$(BENCH_ENV) build/bench/bench --out bench/results | tee bench/results/bench.txt

bench-quick: build/bench/bench
	@mkdir -p build/bench-quick
	$(BENCH_ENV) build/bench/bench --quick --out build/bench-quick

clean:
	rm -rf build
