// A small C shim over TetGen 1.5's C++ library interface (Debian's libtet).
//
// Rust cannot call C++ directly and bindgen cannot reach tetgenio's inline
// members, so this file copies plain arrays into a `tetgenio`, calls
// `tetrahedralize(switches, in, out)` and hands the output arrays back through
// a C struct. Every C++ exception is caught here: none may unwind into Rust.
//
// Error handling. TetGen reports errors by calling `terminatetetgen(m, code)`.
// The version in Debian's tetgen.h frees the mesh (`m->freememory()`) and then
// throws the code; the mesh is a local object of `tetrahedralize()`, whose
// destructor frees it a second time during unwinding, so a plain try/catch
// ends in a double free. The header's function is `inline`, so the library
// exports it as a weak symbol: the strong definition below (which only throws)
// replaces it in every call the library makes, and the destructor frees the
// mesh exactly once. The header's own definition is renamed away by the macro
// around the #include so that the two do not clash in this translation unit.

#define terminatetetgen tetgen_header_terminatetetgen_unused
#include <tetgen.h>
#undef terminatetetgen

#include <new>
#include <cstring>

void terminatetetgen(tetgenmesh *m, int x)
{
  (void) m;  // the mesh is freed by its destructor while the exception unwinds
  throw x;
}

extern "C" {

// Input arrays; see `RawInput` in lib.rs for the meaning of each field.
typedef struct {
  int npoints;
  const double *points;
  int nfacets;
  const int *facet_polygon_counts;
  const int *polygon_vertex_counts;
  const int *polygon_vertices;
  const int *facet_markers;
  const int *facet_hole_counts;
  const double *facet_holes;
  int nholes;
  const double *holes;
  int nregions;
  const double *regions;
  int ntets;
  const int *tets;
  const double *tet_attributes;
  const double *point_sizes;
  int ntrifaces;
  const int *trifaces;
  const int *trifacemarkers;
} tg_input;

// Output arrays, owned by the `tetgenio` behind `io`; see `RawOutput` in lib.rs.
typedef struct {
  void *io;
  int firstnumber;
  int npoints;
  const double *points;
  int ntets;
  int ncorners;
  const int *tets;
  int nattributes;
  const double *tet_attributes;
  int ntrifaces;
  const int *trifaces;
  const int *trifacemarkers;
} tg_output;

}  // extern "C"

template <typename T>
static T *copy_array(const T *src, long n)
{
  if (src == NULL || n <= 0) {
    return NULL;
  }
  T *dst = new T[n];
  std::memcpy(dst, src, sizeof(T) * (size_t) n);
  return dst;
}

// Fills `io` from `in` (copies: `io` owns everything and frees it with delete[]).
static void fill_input(const tg_input *in, tetgenio *io)
{
  io->firstnumber = 0;
  io->mesh_dim = 3;
  io->numberofpoints = in->npoints;
  io->pointlist = copy_array(in->points, 3L * in->npoints);
  if (in->point_sizes != NULL) {
    io->numberofpointmtrs = 1;
    io->pointmtrlist = copy_array(in->point_sizes, (long) in->npoints);
  }

  if (in->nfacets > 0) {
    io->numberoffacets = in->nfacets;
    io->facetlist = new tetgenio::facet[in->nfacets];
    if (in->facet_markers != NULL) {
      io->facetmarkerlist = copy_array(in->facet_markers, (long) in->nfacets);
    }
    long poly = 0, vert = 0, fhole = 0;
    for (int i = 0; i < in->nfacets; i++) {
      tetgenio::facet *f = &io->facetlist[i];
      tetgenio::init(f);
      f->numberofpolygons = in->facet_polygon_counts[i];
      f->polygonlist = new tetgenio::polygon[f->numberofpolygons];
      for (int j = 0; j < f->numberofpolygons; j++) {
        tetgenio::polygon *p = &f->polygonlist[j];
        tetgenio::init(p);
        p->numberofvertices = in->polygon_vertex_counts[poly++];
        p->vertexlist = copy_array(in->polygon_vertices + vert, (long) p->numberofvertices);
        vert += p->numberofvertices;
      }
      if (in->facet_hole_counts != NULL && in->facet_hole_counts[i] > 0) {
        f->numberofholes = in->facet_hole_counts[i];
        f->holelist = copy_array(in->facet_holes + 3 * fhole, 3L * f->numberofholes);
        fhole += f->numberofholes;
      }
    }
  }

  io->numberofholes = in->nholes;
  io->holelist = copy_array(in->holes, 3L * in->nholes);
  io->numberofregions = in->nregions;
  io->regionlist = copy_array(in->regions, 5L * in->nregions);

  if (in->ntets > 0) {
    io->numberoftetrahedra = in->ntets;
    io->numberofcorners = 4;
    io->tetrahedronlist = copy_array(in->tets, 4L * in->ntets);
    if (in->tet_attributes != NULL) {
      io->numberoftetrahedronattributes = 1;
      io->tetrahedronattributelist = copy_array(in->tet_attributes, (long) in->ntets);
    }
  }
  if (in->ntrifaces > 0) {
    io->numberoftrifaces = in->ntrifaces;
    io->trifacelist = copy_array(in->trifaces, 3L * in->ntrifaces);
    io->trifacemarkerlist = copy_array(in->trifacemarkers, (long) in->ntrifaces);
  }
}

extern "C" {

// Runs TetGen with `switches` on `in`. Returns 0 and fills `out` on success
// (release it with tg_output_free); otherwise returns TetGen's error code
// (1 out of memory, 2 internal error, 3 self-intersection, 4 small feature,
// 5 close facets, 10 input error), -1 for an unknown C++ exception, and
// leaves `out` empty.
int tg_tetrahedralize(const char *switches, const tg_input *in, tg_output *out)
{
  std::memset(out, 0, sizeof(tg_output));
  tetgenio *input = NULL;
  tetgenio *output = NULL;
  int code = 0;
  try {
    input = new tetgenio;
    output = new tetgenio;
    fill_input(in, input);
    // TetGen's signature takes a non-const char*; it only parses the string.
    size_t n = std::strlen(switches);
    char *sw = new char[n + 1];
    std::memcpy(sw, switches, n + 1);
    try {
      tetrahedralize(sw, input, output);
    } catch (...) {
      delete[] sw;
      throw;
    }
    delete[] sw;
  } catch (int x) {
    code = x > 0 ? x : 2;
  } catch (std::bad_alloc &) {
    code = 1;
  } catch (...) {
    code = -1;
  }
  delete input;
  if (code != 0) {
    delete output;
    return code;
  }
  out->io = output;
  out->firstnumber = output->firstnumber;
  out->npoints = output->numberofpoints;
  out->points = output->pointlist;
  out->ntets = output->numberoftetrahedra;
  out->ncorners = output->numberofcorners;
  out->tets = output->tetrahedronlist;
  out->nattributes = output->numberoftetrahedronattributes;
  out->tet_attributes = output->tetrahedronattributelist;
  out->ntrifaces = output->numberoftrifaces;
  out->trifaces = output->trifacelist;
  out->trifacemarkers = output->trifacemarkerlist;
  return 0;
}

// Frees what tg_tetrahedralize returned in `out` and clears it.
void tg_output_free(tg_output *out)
{
  if (out != NULL) {
    delete (tetgenio *) out->io;
    std::memset(out, 0, sizeof(tg_output));
  }
}

}  // extern "C"
