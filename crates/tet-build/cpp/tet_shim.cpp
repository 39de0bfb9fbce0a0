// tet-build's C ABI shim around TetGen 1.5 (compiled with -DTETLIBRARY, so
// terminatetetgen() throws an int instead of calling exit()). Every C++
// exception is caught here: nothing unwinds into Rust.
#include "tet_shim.h"
#include "tetgen.h"

#include <climits>
#include <cstdio>
#include <new>
#include <unistd.h>

namespace {
struct Result {
    tetgenio out;
};

// TetGen's own driver (tetrahedralize() in tetgen.cxx) reduced to the
// switches tet-build writes (-p, -Y, -c, -n/-nn, -q, -S, -O, -o/, -T, -z,
// -Q), with one change: -S<n> caps the Steiner points of the quality
// refinement alone. TetGen counts the points its boundary recovery added
// (thousands on some scenes) against -S too, so a cap smaller than those
// stopped the refinement before it began.
int run_tetgen(tetgenbehavior *b, tetgenio *in, tetgenio *out) {
    tetgenmesh m;
    m.b = b;
    m.in = in;
    m.addin = nullptr;
    m.initializepools();
    m.transfernodes();
    if (exactinit(b->verbose, b->noexact, b->nostaticfilter, m.xmax - m.xmin,
                  m.ymax - m.ymin, m.zmax - m.zmin) != 0) {
        return 1;
    }
    clock_t ts = clock();
    m.incrementaldelaunay(ts);
    m.meshsurface();
    if (b->nobisect) {
        m.recoverboundary(ts);
    } else {
        m.constraineddelaunay(ts);
    }
    m.carveholes();
    if (b->nobisect) {
        if (m.subvertstack->objects > 0l) {
            m.suppresssteinerpoints();
        }
        m.recoverdelaunay();
    }
    if (b->quality) {
        if (b->steinerleft > 0) {
            long recovery = m.st_segref_count + m.st_facref_count + m.st_volref_count;
            long cap = (long)b->steinerleft + recovery;
            b->steinerleft = cap > INT_MAX ? INT_MAX : (int)cap;
        }
        m.delaunayrefinement();
    }
    if (b->optlevel > 0) {
        m.optimizemesh();
    }
    if (!b->nojettison && (m.dupverts > 0 || m.unuverts > 0)) {
        m.jettisonnodes();
    }
    out->firstnumber = in->firstnumber;
    out->mesh_dim = in->mesh_dim;
    m.outnodes(out);
    if (m.tetrahedrons->items > 0l) {
        m.outelements(out);
    }
    if (m.subfaces->items > 0l) {
        m.outsubfaces(out);
    }
    m.outsubsegments(out);
    if (b->neighout) {
        m.outneighbors(out);
    }
    return 0;
}
}

extern "C" int32_t tetshim_tetrahedralize(const double *points, int32_t npoints,
                                          const int32_t *triangles, const int32_t *markers,
                                          int32_t ntriangles, const char *switches,
                                          int32_t library_driver, void **handle,
                                          TetShimView *view) {
    *handle = nullptr;
    if (npoints < 0 || ntriangles < 0 || points == nullptr ||
        (ntriangles > 0 && triangles == nullptr)) {
        return TETSHIM_BAD_INPUT;
    }
    Result *res = nullptr;
    try {
        tetgenbehavior b;
        if (!b.parse_commandline(switches)) {
            return TETSHIM_BAD_SWITCHES;
        }
        tetgenio in;
        in.firstnumber = 0;
        in.numberofpoints = npoints;
        in.pointlist = new double[3 * (size_t)npoints];
        for (size_t i = 0; i < 3 * (size_t)npoints; ++i) in.pointlist[i] = points[i];
        in.numberoffacets = ntriangles;
        if (ntriangles > 0) {
            in.facetlist = new tetgenio::facet[ntriangles];
            in.facetmarkerlist = new int[ntriangles];
            for (int32_t t = 0; t < ntriangles; ++t) {
                tetgenio::facet &f = in.facetlist[t];
                tetgenio::init(&f);
                f.numberofpolygons = 1;
                f.polygonlist = new tetgenio::polygon[1];
                tetgenio::init(&f.polygonlist[0]);
                f.polygonlist[0].numberofvertices = 3;
                f.polygonlist[0].vertexlist = new int[3];
                for (int k = 0; k < 3; ++k) {
                    int v = triangles[3 * (size_t)t + k];
                    if (v < 0 || v >= npoints) return TETSHIM_BAD_INPUT;
                    f.polygonlist[0].vertexlist[k] = v;
                }
                in.facetmarkerlist[t] = markers ? markers[t] : t + 1;
            }
        }
        res = new Result();
        int status = library_driver ? tetrahedralize(&b, &in, &res->out, nullptr, nullptr)
                                    : run_tetgen(&b, &in, &res->out);
        if (status != 0) {
            delete res;
            return TETSHIM_FLAT_INPUT;
        }
    } catch (int code) {
        delete res;
        return code;
    } catch (std::bad_alloc &) {
        delete res;
        return 1;
    } catch (...) {
        delete res;
        return TETSHIM_UNKNOWN_EXCEPTION;
    }
    tetgenio &o = res->out;
    view->npoints = o.numberofpoints;
    view->points = o.pointlist;
    view->ntets = o.numberoftetrahedra;
    view->tets = o.tetrahedronlist;
    view->neighbors = o.neighborlist;
    view->nfaces = o.numberoftrifaces;
    view->faces = o.trifacelist;
    view->face_markers = o.trifacemarkerlist;
    view->face_tets = o.adjtetlist;
    *handle = res;
    return TETSHIM_OK;
}

extern "C" void tetshim_free(void *handle) {
    delete static_cast<Result *>(handle);
}

extern "C" int32_t tetshim_redirect_stdout(void) {
    fflush(stdout);
    int saved = dup(1);
    if (saved < 0) return -1;
    if (dup2(2, 1) < 0) {
        close(saved);
        return -1;
    }
    return saved;
}
