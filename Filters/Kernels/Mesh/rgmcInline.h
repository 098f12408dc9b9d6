// RGMC_INLINE: for the small functions on the kernel's hot paths (reading a cube, a vertex's
// key, a cube's found-bit), which sit in several layers of templates and must not become calls:
// left to itself the compiler makes some of them calls, and a call costs as much as the step.
#ifndef rgmcInline_h
#define rgmcInline_h

// RGMC_NOINLINE: for the rarer work inside such a path (visiting a cube growth reached), kept
// out of it so that the common steps keep their values in registers.
#if defined(__GNUC__) || defined(__clang__)
#define RGMC_INLINE inline __attribute__((always_inline))
#define RGMC_NOINLINE __attribute__((noinline))
#else
#define RGMC_INLINE inline
#define RGMC_NOINLINE
#endif

#endif
