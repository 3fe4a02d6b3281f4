// Loops that run across points or vertices in vector registers and still give the bits of one value
// at a time: every value goes through the same operations in the same order, so only the width of the
// registers changes. No fused multiply-add is ever enabled (FMA rounds once where a*b+c rounds twice),
// and the build's ISO C++ mode keeps the compiler from contracting on its own.
#pragma once

// On x86-64 with GCC, the function is built twice, for the baseline (SSE2) and for AVX2 (four doubles a
// register, no FMA), and the loader picks the one the processor runs. A build may define it empty
// (-DHAIRGEN_VECTOR_CLONES=) to keep the baseline alone, e.g. to check both give the same bytes.
#ifndef HAIRGEN_VECTOR_CLONES
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define HAIRGEN_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define HAIRGEN_VECTOR_CLONES
#endif
#endif

// Before a loop whose arrays never overlap: the compiler then needs no run-time overlap checks, which
// past a handful of arrays make it give up vectorising.
#if defined(__GNUC__) && !defined(__clang__)
#define HAIRGEN_IVDEP _Pragma("GCC ivdep")
#else
#define HAIRGEN_IVDEP
#endif
