// C ABI of tet-build's TetGen shim. Our own code (MIT/Apache); it links
// TetGen 1.5 (AGPL-3.0), whose source comes from the `tritet` crate.
#pragma once
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

// Read-only view of TetGen's output, valid until tetshim_free(handle).
typedef struct TetShimView {
    int32_t npoints;
    const double *points;      // 3 * npoints
    int32_t ntets;
    const int32_t *tets;       // 4 * ntets (0-based)
    const int32_t *neighbors;  // 4 * ntets or NULL; -1 = none; k-th is opposite corner k
    int32_t nfaces;
    const int32_t *faces;      // 3 * nfaces (constrained/boundary faces, 0-based)
    const int32_t *face_markers; // nfaces or NULL
    const int32_t *face_tets;  // 2 * nfaces or NULL (only with -nn); -1 = none
} TetShimView;

// Status codes returned by tetshim_tetrahedralize.
#define TETSHIM_OK 0
#define TETSHIM_BAD_SWITCHES -1
#define TETSHIM_BAD_INPUT -2
#define TETSHIM_FLAT_INPUT -3
#define TETSHIM_UNKNOWN_EXCEPTION -4
// Positive values are TetGen's terminatetetgen() codes (1 out of memory,
// 2 internal error, 3 self-intersection, 4 small feature, 5 close facets,
// 10 input error, 0 stopped).

// library_driver = 0 runs the shim's driver (-S caps the refinement's
// Steiner points alone); 1 runs TetGen's tetrahedralize() (for comparison).
int32_t tetshim_tetrahedralize(const double *points, int32_t npoints,
                               const int32_t *triangles, const int32_t *markers,
                               int32_t ntriangles, const char *switches,
                               int32_t library_driver, void **handle,
                               TetShimView *view);

void tetshim_free(void *handle);

// Points C stdout (fd 1) at stderr (fd 2) so TetGen's messages cannot
// corrupt a worker's reply; returns a duplicate of the original stdout, or -1.
int32_t tetshim_redirect_stdout(void);

#ifdef __cplusplus
}
#endif
