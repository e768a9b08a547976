#!/bin/sh
# test_cuda.sh - the CUDA companion (frames_cuda.cu, issue 16). Where nvcc is found (on the
# PATH or in /usr/local/cuda/bin) it compiles frames_cuda.cu in double for sm_80 and sm_90
# in one nvcc invocation with warnings as errors (one case; its time is printed); where a
# GPU is present (nvidia-smi -L lists one) it also builds tests/cuda_frames.c against it
# and runs the GPU tests (their cases count). Without nvcc, or without a GPU for the second
# part, one line says what was skipped. Prints `RESULT <passed> <failed>`
# (tests/summarize.sh).
#
#   sh tests/test_cuda.sh TMP_DIR
#
# Run by the Makefile as build/cuda/test_cuda.result; about 25 s of nvcc on 2 cores.
tmp=$1
mkdir -p "$tmp"
NVCC=$(command -v nvcc 2>/dev/null)
[ -z "$NVCC" ] && [ -x /usr/local/cuda/bin/nvcc ] && NVCC=/usr/local/cuda/bin/nvcc
if [ -z "$NVCC" ]; then
    echo "(nvcc not found on the PATH or in /usr/local/cuda/bin: frames_cuda.cu is not compiled, the GPU tests are skipped)"
    echo "RESULT 0 0"
    exit 0
fi
passed=0
failed=0
GENCODE="-gencode arch=compute_80,code=sm_80 -gencode arch=compute_90,code=sm_90"
start=$(date +%s)
if "$NVCC" -O2 $GENCODE -Werror all-warnings -Xcompiler -Wall,-Wextra,-Werror -c frames_cuda.cu -o "$tmp/frames_cuda.o" \
    > "$tmp/nvcc.log" 2>&1; then
    echo "PASS nvcc frames_cuda.cu (double, sm_80 + sm_90, -Werror): $(( $(date +%s) - start )) s"
    passed=$((passed + 1))
else
    echo "FAIL nvcc frames_cuda.cu (double, sm_80 + sm_90, -Werror):"
    head -n 40 "$tmp/nvcc.log"
    failed=$((failed + 1))
fi
if [ "$failed" -eq 0 ] && command -v nvidia-smi >/dev/null 2>&1 && nvidia-smi -L 2>/dev/null | grep -q GPU; then
    CUDA_LIB=$(dirname "$(dirname "$NVCC")")/lib64
    if gcc -std=c99 -O2 -Wall -Wextra -pedantic -Werror -o "$tmp/cuda_frames" tests/cuda_frames.c "$tmp/frames_cuda.o" \
        -L"$CUDA_LIB" -lcudart -lstdc++ -lm > "$tmp/gcc.log" 2>&1; then
        LD_LIBRARY_PATH="$CUDA_LIB:$LD_LIBRARY_PATH" "$tmp/cuda_frames" > "$tmp/run.log" 2>&1
        cat "$tmp/run.log"
        set -- $(grep '^RESULT ' "$tmp/run.log" || echo "RESULT 0 1")
        passed=$((passed + $2))
        failed=$((failed + $3))
    else
        echo "FAIL the GPU test program did not build:"
        head -n 40 "$tmp/gcc.log"
        failed=$((failed + 1))
    fi
else
    [ "$failed" -eq 0 ] && echo "(no GPU: the GPU tests of frames_cuda.cu are skipped; bench/gpu.sh runs them where one is)"
fi
echo "RESULT $passed $failed"
[ "$failed" -eq 0 ]
