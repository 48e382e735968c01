/*
** The instruction sets of the vectorised batches (model/law_simd.h: the law's lanes, the lattice's
** spring sweep) and the level the process runs. Internal: a program using the library gets the
** processor's widest level, lowered by CONIFIT_SIMD, without asking.
*/
#ifndef CF_MODEL_SIMD_H
#define CF_MODEL_SIMD_H

/* Instruction sets of the vectorised batches (the law's lanes, the lattice's spring sweep), each
** the former's superset. Processors without AVX2 run the baseline copy. */
typedef enum { CF_SIMD_SSE2 = 0, CF_SIMD_AVX2 = 1, CF_SIMD_AVX512 = 2 } cf_simd;

/* The widest instruction set the batches may use: the processor's, lowered by the environment
** variable CONIFIT_SIMD ("sse2", "avx2" or "avx512"; unset or empty for no limit). A build without
** the copies (clang, the sanitizer build, other processors) always gives CF_SIMD_SSE2. Read once.
** cf_simd_level_supported gives the processor's alone; cf_simd_parse returns -1 for a name not in
** the list; cf_simd_name gives a level's name. */
cf_simd cf_simd_level(void);
cf_simd cf_simd_level_supported(void);
int cf_simd_parse(const char *name);
const char *cf_simd_name(cf_simd level);

#endif
