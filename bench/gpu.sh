#!/bin/sh
# gpu.sh - everything of issue 16 that needs a GPU, in one go (GPU time is scarce): builds
# frames_cuda.cu (double and float, sm_80 and sm_90), runs the GPU tests (tests/cuda_frames.c)
# in both precisions and the GPU bench (bench/gpu_bench.c: the thesis's 34,610-sample
# step at 60 CG iterations and 1e6 samples, device and CPU of the same run), and writes
# every output under bench/results/gpu-<name>/ (name: the argument, else the GPU's name).
#
#   sh bench/gpu.sh [name] [max_samples]
#
# Needs nvcc (PATH or /usr/local/cuda/bin), gcc with OpenMP, a GPU. About 2 minutes of
# building and 1-3 minutes of running on an H100-class machine (estimate: not yet run).
set -u
cd "$(dirname "$0")/.."
NVCC=$(command -v nvcc 2>/dev/null || true)
[ -z "$NVCC" ] && [ -x /usr/local/cuda/bin/nvcc ] && NVCC=/usr/local/cuda/bin/nvcc
[ -z "$NVCC" ] && { echo "gpu.sh: nvcc not found"; exit 1; }
CUDA_LIB=$(dirname "$(dirname "$NVCC")")/lib64
gpu=$(nvidia-smi --query-gpu=name --format=csv,noheader 2>/dev/null | head -n 1)
[ -z "$gpu" ] && { echo "gpu.sh: no GPU (nvidia-smi lists none)"; exit 1; }
name=${1:-$(echo "$gpu" | tr -c 'A-Za-z0-9\n' '-' | tr 'A-Z' 'a-z' | sed 's/--*/-/g; s/-$//')}
max=${2:-1100000}
out=bench/results/gpu-$name
tmp=build/gpu
mkdir -p "$out" "$tmp"
GENCODE="-gencode arch=compute_80,code=sm_80 -gencode arch=compute_90,code=sm_90"
{
    echo "GPU: $gpu"
    nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv 2>/dev/null
    "$NVCC" --version | tail -n 2
    echo "CPU: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2) x $(nproc)"
    echo "commit: $(git rev-parse --short HEAD 2>/dev/null)$(git diff --quiet HEAD -- . 2>/dev/null || echo -dirty)"
    date -u
} > "$out/machine.txt"
status=0
for prec in double float; do
    def=""; [ "$prec" = float ] && def="-DFRM_REAL=float"
    "$NVCC" -O3 $GENCODE $def -Werror all-warnings -Xcompiler -Wall,-Wextra,-Werror -Xptxas -v -c frames_cuda.cu \
        -o "$tmp/frames_cuda_$prec.o" > "$out/nvcc_$prec.log" 2>&1 || { echo "nvcc ($prec) failed"; status=1; continue; }
    gcc -std=c99 -O2 $def -Wall -Wextra -pedantic -Werror -o "$tmp/cuda_frames_$prec" tests/cuda_frames.c \
        "$tmp/frames_cuda_$prec.o" -L"$CUDA_LIB" -lcudart -lstdc++ -lm || { status=1; continue; }
    gcc -std=c99 -O3 -march=native -fopenmp $def -Wall -Wextra -Werror -o "$tmp/gpu_bench_$prec" bench/gpu_bench.c \
        "$tmp/frames_cuda_$prec.o" -L"$CUDA_LIB" -lcudart -lstdc++ -lm || { status=1; continue; }
    LD_LIBRARY_PATH="$CUDA_LIB:${LD_LIBRARY_PATH:-}" "$tmp/cuda_frames_$prec" > "$out/tests_$prec.txt" 2>&1 || status=1
    tail -n 1 "$out/tests_$prec.txt"
    OMP_WAIT_POLICY=passive LD_LIBRARY_PATH="$CUDA_LIB:${LD_LIBRARY_PATH:-}" "$tmp/gpu_bench_$prec" "$max" \
        > "$out/bench_$prec.txt" 2>&1 || status=1
    cat "$out/bench_$prec.txt"
done
echo "results in $out (status $status)"
exit $status
