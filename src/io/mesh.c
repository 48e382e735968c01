/*
** Volume meshes through Gmsh's library (gmshc.h, Gmsh 4.8 C API): any file Gmsh opens (.msh of
** every version, and the other formats it reads) becomes a cf_mesh (body.h) of linear tetrahedra;
** a box meshed by Gmsh with an element size that grows away from a point serves the tests and
** examples. Every use of Gmsh runs in a process of its own (io/isolate.h: a Gmsh that loops,
** exhausts memory or aborts ends in an error, not in its caller; its one global model is that
** process's alone), after the mesh's cost is checked against the limits (cf_mesh_limits); the
** mesh comes back through a pipe (mesh_nodes.h). Gmsh's messages are switched off (the library
** prints nothing) and its last error is read back into the message.
*/
#include "io/mesh.h"

#include "base/dynlib.h"

#include "io/isolate.h"
#include "io/mesh_nodes.h"
#include "io/surface.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <stdint.h>

#include <gmshc.h>

static int gmsh_ready;

/* Gmsh's process: the library and its model before a mesh (bytes), and what it holds per
** tetrahedron while it refines a mesh or fills a surface (per tetrahedron of the estimate).
** Measured as the peak resident memory of its process: 46 MiB for liver2.msh, 211 MiB refined
** three times (764,416 tetrahedra: 232 bytes each); 146 MiB filling a 10 mm cube at 0.3 mm
** (178,818 tetrahedra, 570 bytes each; 314,000 estimated, 325 bytes each). */
#define GMSH_BYTES_BASE (64.0 * 1024 * 1024)
#define GMSH_REFINE_TET_BYTES 260.0
#define GMSH_FILL_TET_BYTES 600.0

/* Gmsh's library is loaded when a mesh is first read, not linked: it is large (with its
** geometry kernel it adds tens of megabytes to a process), and a run that reads no mesh should
** not carry it. Its functions, by their own names. */
#define GMSH_FUNCTIONS(X)                                                                          \
    X(gmshClear) X(gmshFinalize) X(gmshFree) X(gmshInitialize) X(gmshLoggerGetLastError)           \
    X(gmshModelAdd) X(gmshModelMeshFieldAdd) X(gmshModelMeshFieldSetAsBackgroundMesh)              \
    X(gmshModelMeshFieldSetString) X(gmshModelMeshGenerate) X(gmshModelMeshGetElements)            \
    X(gmshModelMeshGetNodes) X(gmshModelMeshRefine) X(gmshModelOccAddBox)                          \
    X(gmshModelOccSynchronize) X(gmshOpen) X(gmshOptionSetNumber) X(gmshModelGetPhysicalGroups)     \
    X(gmshModelGetPhysicalName) X(gmshModelMeshGetNodesForPhysicalGroup)                          \
    X(gmshModelAddDiscreteEntity) X(gmshModelMeshAddNodes) X(gmshModelMeshAddElementsByType)      \
    X(gmshModelMeshClassifySurfaces) X(gmshModelMeshCreateGeometry) X(gmshModelGetEntities)       \
    X(gmshModelGeoAddSurfaceLoop) X(gmshModelGeoAddVolume) X(gmshModelGeoSynchronize)
#define GMSH_FIELD(f) __typeof__(&f) f;
static struct {
    GMSH_FUNCTIONS(GMSH_FIELD)
} gm;
static void *gmsh_handle;

/* Loads the library (once); 0 with the reason in why when it cannot. */
static int gmsh_load(char *why, size_t cap)
{
    if (gmsh_handle)
        return 1;
    char soname[64];
    snprintf(soname, sizeof soname, "libgmsh.so.%d.%d", GMSH_API_VERSION_MAJOR,
             GMSH_API_VERSION_MINOR);
    const char *names[] = {soname, "libgmsh.so", NULL};
    cf_error err = {0};
    void *h = cf_dynlib_open("Gmsh", names, &err);
#define GMSH_BIND(f)                                                                               \
    if (h && !(*(void **)(&gm.f) = cf_dynlib_sym(h, soname, #f, &err))) {                          \
        cf_dynlib_close(h);                                                                        \
        h = NULL;                                                                                  \
    }
    GMSH_FUNCTIONS(GMSH_BIND)
#undef GMSH_BIND
    if (!h) { /* the message, cut to the caller's buffer */
        const size_t m = strnlen(err.msg, cap - 1);
        memcpy(why, err.msg, m);
        why[m] = '\0';
        return 0;
    }
    gmsh_handle = h;
    return 1;
}

/* Starts Gmsh once (quiet) and clears its model. Returns 0 on failure. */
static int gmsh_begin(char *why, size_t cap)
{
    int ierr = 0;
    if (!gmsh_load(why, cap))
        return 0;
    snprintf(why, cap, "Gmsh could not start");
    if (!gmsh_ready) {
        char prog[] = "conifit";
        char *argv[] = {prog, NULL};
        gm.gmshInitialize(1, argv, 0, &ierr);
        if (ierr)
            return 0;
        gmsh_ready = 1;
    }
    gm.gmshOptionSetNumber("General.Terminal", 0, &ierr);
    gm.gmshOptionSetNumber("General.Verbosity", 0, &ierr);
    gm.gmshClear(&ierr);
    return ierr == 0;
}

static const char *gmsh_reason(char *buf, size_t cap)
{
    char *msg = NULL;
    int ierr = 0;
    gm.gmshLoggerGetLastError(&msg, &ierr);
    snprintf(buf, cap, "%s", msg && *msg && !ierr ? msg : "Gmsh could not read it");
    if (msg)
        gm.gmshFree(msg);
    for (char *p = buf; *p; p++) /* one line, printable */
        if ((unsigned char)*p < 32)
            *p = ' ';
    return buf;
}

static int cmp_size(const void *a, const void *b)
{
    size_t x = *(const size_t *)a, y = *(const size_t *)b;
    return (x > y) - (x < y);
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* Corner count and tetrahedra of Gmsh element type t: linear or higher-order tetrahedra (their
** four corners) and hexahedra (six tetrahedra around the diagonal from corner 0 to corner 6). */
static int volume_type(int t, int *corners, int *tets)
{
    switch (t) {
    case 4: case 11: case 29: case 30: case 31:
        *corners = 4;
        *tets = 1;
        return 1;
    case 5: case 12: case 17: case 92: case 93:
        *corners = 8;
        *tets = 6;
        return 1;
    default:
        return 0;
    }
}

/* The current Gmsh model's physical groups into m: each group's nodes among the nn used ones
** (their tags in sorted); a node of a group that no volume element uses is left out. */
static cf_status extract_groups(const char *name, cf_mesh *m, const size_t *sorted, size_t nn,
                                cf_error *err)
{
    int ierr = 0, *dt = NULL;
    size_t ndt = 0;
    gm.gmshModelGetPhysicalGroups(&dt, &ndt, -1, &ierr);
    if (ierr || ndt == 0) {
        gm.gmshFree(dt);
        return CF_OK; /* no groups */
    }
    cf_status st = CF_OK;
    m->groups = calloc(ndt / 2, sizeof *m->groups);
    if (!m->groups) {
        gm.gmshFree(dt);
        return cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the mesh's groups", name);
    }
    for (size_t k = 0; k + 1 < ndt && st == CF_OK; k += 2) {
        cf_mesh_group *g = &m->groups[m->ngroups++];
        g->dim = dt[k];
        g->tag = dt[k + 1];
        char *gname = NULL;
        gm.gmshModelGetPhysicalName(g->dim, g->tag, &gname, &ierr);
        snprintf(g->name, sizeof g->name, "%s", !ierr && gname ? gname : "");
        gm.gmshFree(gname);
        size_t *tags = NULL, ntags = 0, ncoord = 0;
        double *coord = NULL;
        gm.gmshModelMeshGetNodesForPhysicalGroup(g->dim, g->tag, &tags, &ntags, &coord, &ncoord,
                                                 &ierr);
        g->nodes = malloc((ntags ? ntags : 1) * sizeof *g->nodes);
        if (!g->nodes)
            st = cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the mesh's groups", name);
        for (size_t j = 0; g->nodes && !ierr && j < ntags; j++) {
            const size_t *hit = bsearch(&tags[j], sorted, nn, sizeof *sorted, cmp_size);
            if (hit)
                g->nodes[g->nnodes++] = (uint32_t)(hit - sorted);
        }
        gm.gmshFree(tags);
        gm.gmshFree(coord);
        if (g->nodes)
            qsort(g->nodes, g->nnodes, sizeof *g->nodes, cmp_u32);
    }
    gm.gmshFree(dt);
    return st;
}

/* The tags of the nodes the volume elements use at their corners, sorted and each once, into
** sorted; returns how many. */
static size_t used_nodes(const int *types, size_t ntypes, const size_t *etags_n,
                         size_t *const *ntags, const size_t *ntags_n, size_t *sorted)
{
    size_t nused = 0;
    for (size_t k = 0; k < ntypes; k++) {
        int corners = 4, per = 1;
        volume_type(types[k], &corners, &per);
        size_t stride = etags_n[k] ? ntags_n[k] / etags_n[k] : 0;
        for (size_t e = 0; e < etags_n[k]; e++)
            for (int c = 0; c < corners; c++)
                sorted[nused++] = ntags[k][e * stride + (size_t)c];
    }
    qsort(sorted, nused, sizeof *sorted, cmp_size);
    size_t nn = 0;
    for (size_t i = 0; i < nused; i++)
        if (i == 0 || sorted[i] != sorted[nn - 1])
            sorted[nn++] = sorted[i];
    return nn;
}

/* The mesh's nodes: their tags (sorted, nn of them) and their coordinates times unit_mm, looked
** up among Gmsh's nodes (tags, coord); a node no Gmsh node defines is left NAN. Returns the index
** into tags of a node given twice at different places (the file defines it twice), or tags_n. */
static size_t fill_nodes(cf_mesh *m, const size_t *sorted, size_t nn, const size_t *tags,
                         size_t tags_n, const double *coord, double unit_mm)
{
    for (size_t i = 0; i < nn; i++)
        m->id[i] = (uint32_t)(sorted[i] <= UINT32_MAX ? sorted[i] : 0);
    for (size_t i = 0; i < nn; i++)
        m->X[3 * i] = NAN;
    for (size_t j = 0; j < tags_n; j++) {
        size_t *hit = bsearch(&tags[j], sorted, nn, sizeof *sorted, cmp_size);
        if (!hit)
            continue;
        double *x = m->X + 3 * (size_t)(hit - sorted);
        if (!isnan(x[0]) && (x[0] != coord[3 * j] * unit_mm || x[1] != coord[3 * j + 1] * unit_mm ||
                             x[2] != coord[3 * j + 2] * unit_mm))
            return j;
        for (int a = 0; a < 3; a++)
            x[a] = coord[3 * j + a] * unit_mm;
    }
    return tags_n;
}

/* The volume elements as tetrahedra of the mesh's node indices (a hexahedron as six around its
** diagonal 0-6), each with its Gmsh element tag. */
static void fill_elements(cf_mesh *m, const int *types, size_t ntypes, size_t *const *etags,
                          const size_t *etags_n, size_t *const *ntags, const size_t *ntags_n,
                          const size_t *sorted, size_t nn)
{
    size_t t = 0;
    static const int hex_tet[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6},
                                      {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
    for (size_t k = 0; k < ntypes; k++) {
        int corners = 4, per = 1;
        volume_type(types[k], &corners, &per);
        size_t stride = etags_n[k] ? ntags_n[k] / etags_n[k] : 0;
        for (size_t e = 0; e < etags_n[k]; e++) {
            uint32_t v[8];
            for (int c = 0; c < corners; c++) {
                size_t *hit = bsearch(&ntags[k][e * stride + (size_t)c], sorted, nn,
                                      sizeof *sorted, cmp_size);
                v[c] = (uint32_t)(hit - sorted);
            }
            for (int p = 0; p < per; p++, t++) {
                for (int c = 0; c < 4; c++)
                    m->tet[4 * t + c] = corners == 4 ? v[c] : v[hex_tet[p][c]];
                m->eid[t] = etags[k][e];
            }
        }
    }
}

/* The current Gmsh model's volume elements into m (node coordinates times unit_mm). */
static cf_status extract(const char *name, double unit_mm, cf_mesh *m, cf_error *err)
{
    int ierr = 0, *types = NULL;
    size_t ntypes = 0, **etags = NULL, *etags_n = NULL, etags_nn = 0, **ntags = NULL,
           *ntags_n = NULL, ntags_nn = 0, *tags = NULL, tags_n = 0, *sorted = NULL;
    double *coord = NULL, *par = NULL;
    size_t coord_n = 0, par_n = 0;
    cf_status st = CF_OK;
    char why[300];
    memset(m, 0, sizeof *m);
    gm.gmshModelMeshGetElements(&types, &ntypes, &etags, &etags_n, &etags_nn, &ntags, &ntags_n,
                             &ntags_nn, 3, -1, &ierr);
    if (ierr) {
        st = cf_error_set(err, CF_E_DATA, "%s: %s", name, gmsh_reason(why, sizeof why));
        goto end;
    }
    size_t nt = 0;
    for (size_t k = 0; k < ntypes; k++) {
        int corners = 4, per = 1;
        if (!volume_type(types[k], &corners, &per)) {
            st = cf_error_set(err, CF_E_DATA,
                              "%s: element %zu is of Gmsh type %d: only tetrahedra and hexahedra "
                              "are read",
                              name, etags_n[k] ? etags[k][0] : (size_t)0, types[k]);
            goto end;
        }
        nt += etags_n[k] * (size_t)per;
    }
    if (nt == 0) {
        st = cf_error_set(err, CF_E_DATA,
                          "%s: no tetrahedra or hexahedra: not a volume mesh", name);
        goto end;
    }
    gm.gmshModelMeshGetNodes(&tags, &tags_n, &coord, &coord_n, &par, &par_n, -1, -1, 0, 0, &ierr);
    if (ierr || coord_n != 3 * tags_n) {
        st = cf_error_set(err, CF_E_DATA, "%s: %s", name, gmsh_reason(why, sizeof why));
        goto end;
    }
    /* the nodes the volume elements use, in the order of their tags */
    size_t nused = 0;
    for (size_t k = 0; k < ntypes; k++)
        nused += ntags_n[k];
    sorted = malloc((nused ? nused : 1) * sizeof *sorted);
    m->tet = malloc(4 * nt * sizeof *m->tet);
    m->eid = malloc(nt * sizeof *m->eid);
    if (!sorted || !m->tet || !m->eid)
        goto oom;
    const size_t nn = used_nodes(types, ntypes, etags_n, ntags, ntags_n, sorted);
    if (nn > UINT32_MAX) {
        st = cf_error_set(err, CF_E_DATA, "%s: %zu nodes: too many", name, nn);
        goto end;
    }
    m->nn = nn;
    m->X = malloc(3 * nn * sizeof *m->X);
    m->id = malloc(nn * sizeof *m->id);
    if (!m->X || !m->id)
        goto oom;
    const size_t twice = fill_nodes(m, sorted, nn, tags, tags_n, coord, unit_mm);
    if (twice < tags_n) {
        st = cf_error_set(err, CF_E_DATA, "%s: node %zu is defined twice, at different places",
                          name, tags[twice]);
        goto end;
    }
    for (size_t i = 0; i < nn; i++)
        if (isnan(m->X[3 * i])) {
            st = cf_error_set(err, CF_E_DATA, "%s: node %zu is used by an element but not defined",
                              name, sorted[i]);
            goto end;
        }
    fill_elements(m, types, ntypes, etags, etags_n, ntags, ntags_n, sorted, nn);
    m->nt = nt;
    st = extract_groups(name, m, sorted, nn, err);
    goto end;
oom:
    st = cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the mesh", name);
end:
    if (st != CF_OK)
        cf_mesh_free(m);
    free(sorted);
    for (size_t k = 0; k < ntypes; k++) {
        gm.gmshFree(etags ? etags[k] : NULL);
        gm.gmshFree(ntags ? ntags[k] : NULL);
    }
    gm.gmshFree(types);
    gm.gmshFree(etags);
    gm.gmshFree(etags_n);
    gm.gmshFree(ntags);
    gm.gmshFree(ntags_n);
    gm.gmshFree(tags);
    gm.gmshFree(coord);
    gm.gmshFree(par);
    return st;
}

/* The mesh formats read (by the name's ending, which is how Gmsh chooses its reader): files of
** data only. Gmsh opens any other name as a script of its own language, which can run commands,
** so no other name is passed to it (input is data, never code). */
static const char *const mesh_exts[] = {".msh", ".mesh", ".vtk", ".unv", ".bdf", ".nas", NULL};

static int mesh_ext_ok(const char *path)
{
    size_t n = strlen(path);
    for (size_t k = 0; mesh_exts[k]; k++) {
        size_t e = strlen(mesh_exts[k]);
        if (n > e && strcasecmp(path + n - e, mesh_exts[k]) == 0)
            return 1;
    }
    return 0;
}

cf_mesh_limits cf_mesh_limits_default(void)
{
    cf_mesh_limits l = {CF_MESH_MAX_BYTES_DEFAULT, CF_MESH_MAX_SECONDS_DEFAULT, 0};
    return l;
}

/* What a mesh of about `nodes` nodes and `tets` tetrahedra costs, against the limits, before
** Gmsh makes it: Gmsh's process (GMSH_BYTES_BASE and tet_bytes each, measured) and the caller's
** use of its nodes. `what` says how the mesh would be made. */
static cf_status mesh_cost(const char *name, const char *what, double nodes, double tets,
                           double tet_bytes, const cf_mesh_limits *lim, cf_error *err)
{
    const double gmsh = GMSH_BYTES_BASE + tets * tet_bytes, use = nodes * lim->node_bytes;
    if (!(lim->max_bytes > 0) || fmax(gmsh, use) <= lim->max_bytes)
        return CF_OK;
    char uses[80] = "";
    if (use > 0)
        snprintf(uses, sizeof uses, " and %.0f MiB to use", use / 1048576.0);
    return cf_error_set(err, CF_E_DATA, "%s: %s would give about %.3g nodes and %.3g tetrahedra, "
                        "about %.0f MiB for Gmsh to make%s, over the memory limit of %.0f MiB: "
                        "refused before meshing", name, what, nodes, tets, gmsh / 1048576.0,
                        use > 0 ? uses : " them", lim->max_bytes / 1048576.0);
}

/* What Gmsh's process needs: a mesh file and its refinement, or a surface, and the limits. */
typedef struct gmsh_job {
    const char *path;
    double unit_mm;
    int refine;
    const cf_mesh_limits *lim;
    const cf_surface *surface; /* a surface to fill at size h (file units) */
    double h;
    const double *box;         /* a box: lo[3], hi[3], focus[3], near, far, growth, ring */
} gmsh_job;

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Distinct keys among n sorted ones. */
static size_t distinct(uint64_t *k, size_t n)
{
    qsort(k, n, sizeof *k, cmp_u64);
    size_t d = 0;
    for (size_t i = 0; i < n; i++)
        d += i == 0 || k[i] != k[i - 1];
    return d;
}

/* The nodes and tetrahedra of m refined r times, counted exactly from its edges E and faces F:
** each refinement puts a node on every edge (V + E), halves the edges and adds three in each face
** and one in each tetrahedron (2E + 3F + T), splits each face in four and adds eight inside each
** tetrahedron (4F + 8T), each tetrahedron in eight (8T). 0 when memory runs out. */
static int refined_size(const cf_mesh *m, int r, double *nodes, double *tets)
{
    uint64_t *k = malloc((6 * m->nt + 1) * sizeof *k);
    if (!k)
        return 0;
    static const int ed[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    for (size_t t = 0; t < m->nt; t++)
        for (int e = 0; e < 6; e++) {
            uint64_t a = m->tet[4 * t + (size_t)ed[e][0]], b = m->tet[4 * t + (size_t)ed[e][1]];
            k[6 * t + (size_t)e] = a < b ? a << 32 | b : b << 32 | a;
        }
    double E = (double)distinct(k, 6 * m->nt);
    for (size_t t = 0; t < m->nt; t++) /* a face by its three corners, 21 bits each */
        for (int f = 0; f < 4; f++) {
            uint64_t c[3], x;
            for (int j = 0, n = 0; j < 4; j++)
                if (j != f)
                    c[n++] = m->tet[4 * t + (size_t)j];
            if (c[0] > c[1]) x = c[0], c[0] = c[1], c[1] = x;
            if (c[1] > c[2]) x = c[1], c[1] = c[2], c[2] = x;
            if (c[0] > c[1]) x = c[0], c[0] = c[1], c[1] = x;
            k[4 * t + (size_t)f] = c[0] << 42 ^ c[1] << 21 ^ c[2];
        }
    double F = (double)distinct(k, 4 * m->nt), V = (double)m->nn, T = (double)m->nt;
    free(k);
    for (int i = 0; i < r; i++) {
        V += E;
        E = 2 * E + 3 * F + T;
        F = 4 * F + 8 * T;
        T *= 8;
    }
    *nodes = V;
    *tets = T;
    return 1;
}

/* In Gmsh's process: the mesh file read, its cost after refinement checked before refining
** (refined_size), refined, and sent. */
static cf_status read_job(const gmsh_job *j, cf_mesh *m, cf_error *err)
{
    char why[300];
    int ierr = 0;
    gm.gmshOpen(j->path, &ierr);
    if (ierr)
        return cf_error_set(err, CF_E_DATA, "%s: not a mesh Gmsh reads: %s", j->path,
                            gmsh_reason(why, sizeof why));
    cf_status st = extract(j->path, j->unit_mm, m, err);
    if (st != CF_OK || j->refine == 0)
        return st;
    double nodes, tets;
    if (!refined_size(m, j->refine, &nodes, &tets))
        return cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the mesh", j->path);
    char what[80];
    snprintf(what, sizeof what, "refining its %zu tetrahedra %d time%s", m->nt, j->refine,
             j->refine > 1 ? "s" : "");
    st = mesh_cost(j->path, what, nodes, tets, GMSH_REFINE_TET_BYTES, j->lim, err);
    cf_mesh_free(m);
    if (st != CF_OK)
        return st;
    for (int k = 0; k < j->refine && !ierr; k++)
        gm.gmshModelMeshRefine(&ierr);
    if (ierr)
        return cf_error_set(err, CF_E_DATA, "%s: Gmsh could not refine it: %s", j->path,
                            gmsh_reason(why, sizeof why));
    return extract(j->path, j->unit_mm, m, err);
}

static cf_status box_job(const gmsh_job *j, cf_mesh *m, cf_error *err);
static cf_status fill_surface(const char *path, const cf_surface *s, double unit_mm, double h,
                              cf_mesh *m, cf_error *err);

/* Gmsh's process: starts Gmsh, runs the job, sends the mesh. */
static cf_status gmsh_child(void *arg, cf_isolate_buf *out, cf_error *err)
{
    const gmsh_job *j = arg;
    char why[300];
    if (!gmsh_begin(why, sizeof why))
        return cf_error_set(err, CF_E_INTERNAL, "%s: %s", j->path, why);
    cf_isolate_limit_memory(); /* Gmsh's library loaded: its model under the limit */
    cf_mesh m;
    memset(&m, 0, sizeof m);
    cf_status st = j->box       ? box_job(j, &m, err)
                   : j->surface ? fill_surface(j->path, j->surface, j->unit_mm, j->h, &m, err)
                                : read_job(j, &m, err);
    if (st == CF_OK)
        cf_mesh_put(out, &m);
    cf_mesh_free(&m);
    return st;
}

/* Runs the job in Gmsh's own process under the limits and checks the mesh it sends. */
static cf_status gmsh_run(const gmsh_job *j, cf_mesh *m, cf_error *err)
{
    char what[300];
    /* the library loaded here, once: each process of Gmsh starts with it mapped */
    static pthread_mutex_t load_lock = PTHREAD_MUTEX_INITIALIZER;
    pthread_mutex_lock(&load_lock);
    const int loaded = gmsh_load(what, sizeof what);
    pthread_mutex_unlock(&load_lock);
    if (!loaded)
        return cf_error_set(err, CF_E_INTERNAL, "%s: %s", j->path, what);
    snprintf(what, sizeof what, "%s: Gmsh", j->path);
    cf_isolate_buf in;
    cf_status st = cf_isolate_run(what, gmsh_child, (void *)j, j->lim->max_bytes,
                                  j->lim->max_seconds, &in, err);
    if (st == CF_OK) {
        st = cf_mesh_get(&in, j->path, m, err);
        free(in.data);
    }
    if (st == CF_OK && (st = cf_mesh_check(m, j->path, err)) != CF_OK)
        cf_mesh_free(m);
    return st;
}

cf_status cf_mesh_read(const char *path, double unit_mm, cf_mesh *m, cf_error *err)
{
    return cf_mesh_read_refined(path, unit_mm, 0, NULL, m, err);
}

cf_status cf_mesh_read_refined(const char *path, double unit_mm, int refine,
                               const cf_mesh_limits *lim, cf_mesh *m, cf_error *err)
{
    memset(m, 0, sizeof *m);
    const cf_mesh_limits dflt = cf_mesh_limits_default();
    if (!mesh_ext_ok(path))
        return cf_error_set(err, CF_E_DATA, "%s: not a mesh file name: expected .msh, .mesh, "
                            ".vtk, .unv, .bdf or .nas (Gmsh's mesh formats)", path);
    if (refine < 0 || refine > 4)
        return cf_error_set(err, CF_E_DATA, "%s: refinement %d: must be 0 to 4", path, refine);
    if (!(unit_mm > 0) || !isfinite(unit_mm))
        return cf_error_set(err, CF_E_DATA, "%s: unit %g mm: must be finite and > 0", path, unit_mm);
    FILE *f = fopen(path, "rb");
    if (!f)
        return cf_error_set(err, CF_E_NOINPUT, "%s: cannot open mesh: %s", path, strerror(errno));
    fclose(f);
    const gmsh_job j = {path, unit_mm, refine, lim ? lim : &dflt, NULL, 0, NULL};
    cf_status st = cf_mesh_msh_nodes_once(path, err);
    if (st == CF_OK)
        st = gmsh_run(&j, m, err);
    if (st == CF_OK)
        st = cf_mesh_check_coincident(m, path, err);
    return st;
}

/* An upper bound on the number of element-sized cubes in the box lo..hi graded as cf_mesh_box
** grades it (size h0 at focus, growing by g per mm, at most hf): the smaller of the box's volume
** over h0^3 and, the graded part taken as the whole ball about focus that reaches the box's
** farthest corner, the integral of 4 pi x^2 / (h0 + g x)^3 out to where the size reaches hf plus
** the box's volume over hf^3. */
static double box_cells(const double lo[3], const double hi[3], const double focus[3], double h0,
                        double hf, double g)
{
    const double vol = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    const double flat = vol / (h0 * h0 * h0);
    if (!(g > 0))
        return flat;
    double r2 = 0;
    for (int a = 0; a < 3; a++) {
        const double e = fmax(fabs(hi[a] - focus[a]), fabs(focus[a] - lo[a]));
        r2 += e * e;
    }
    /* with u = h0 + g x: (1/g^3) [ln u + 2 h0 / u - h0^2 / (2 u^2)] from h0 to u1 */
    const double u1 = fmin(hf, h0 + g * sqrt(r2));
    const double F1 = log(u1) + 2 * h0 / u1 - h0 * h0 / (2 * u1 * u1);
    const double F0 = log(h0) + 2 - 0.5;
    const double graded = 4 * M_PI * (F1 - F0) / (g * g * g) + vol / (hf * hf * hf);
    return fmin(flat, graded);
}

cf_status cf_mesh_box(const double lo[3], const double hi[3], const double focus[3],
                      double size_near, double size_far, double growth, cf_mesh *m, cf_error *err)
{
    return cf_mesh_box_ring(lo, hi, focus, 0, size_near, size_far, growth, m, err);
}

cf_status cf_mesh_box_ring(const double lo[3], const double hi[3], const double focus[3],
                           double ring_mm, double size_near, double size_far, double growth,
                           cf_mesh *m, cf_error *err)
{
    memset(m, 0, sizeof *m);
    for (int a = 0; a < 3; a++)
        if (!isfinite(lo[a]) || !isfinite(hi[a]) || !(hi[a] > lo[a]) || !isfinite(focus[a]))
            return cf_error_set(err, CF_E_DATA, "box: corner %d is not finite and increasing", a);
    if (!(size_near > 0) || !(size_far >= size_near) || !isfinite(size_far) || !(growth >= 0) ||
        !isfinite(growth))
        return cf_error_set(err, CF_E_DATA, "box: element sizes %g, %g and growth %g: need "
                                            "0 < near <= far and growth >= 0",
                            size_near, size_far, growth);
    if (!(ring_mm >= 0) || !isfinite(ring_mm))
        return cf_error_set(err, CF_E_DATA, "box: ring radius %g mm: need a finite value >= 0",
                            ring_mm);
    /* a ring: the ball's bound once per element length along it (a bound, not an estimate) */
    if (box_cells(lo, hi, focus, size_near, size_far, growth) * (1 + 2 * M_PI * ring_mm / size_near) > 1e8)
        return cf_error_set(err, CF_E_DATA, "box: element size %g mm too small for the box",
                            size_near);
    const double box[13] = {lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], focus[0], focus[1], focus[2],
                            size_near, size_far, growth, ring_mm};
    const cf_mesh_limits dflt = cf_mesh_limits_default();
    const gmsh_job j = {"box", 1, 0, &dflt, NULL, 0, box};
    return gmsh_run(&j, m, err);
}

/* In Gmsh's process: the box of j->box meshed. */
static cf_status box_job(const gmsh_job *j, cf_mesh *m, cf_error *err)
{
    const double *lo = j->box, *hi = j->box + 3, *focus = j->box + 6;
    const double size_near = j->box[9], size_far = j->box[10], growth = j->box[11];
    int ierr = 0;
    char why[300], expr[400];
    gm.gmshModelAdd("box", &ierr);
    gm.gmshModelOccAddBox(lo[0], lo[1], lo[2], hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], -1, &ierr);
    gm.gmshModelOccSynchronize(&ierr);
    int fld = gm.gmshModelMeshFieldAdd("MathEval", -1, &ierr);
    if (j->box[12] > 0) /* the distance from the ring about focus in the plane z = focus z */
        snprintf(expr, sizeof expr, "Min(%.17g, %.17g + %.17g * Sqrt((Sqrt((x - %.17g)^2 + "
                                    "(y - %.17g)^2) - %.17g)^2 + (z - %.17g)^2))",
                 size_far, size_near, growth, focus[0], focus[1], j->box[12], focus[2]);
    else
        snprintf(expr, sizeof expr, "Min(%.17g, %.17g + %.17g * Sqrt((x - %.17g)^2 + (y - %.17g)^2 + "
                                    "(z - %.17g)^2))",
                 size_far, size_near, growth, focus[0], focus[1], focus[2]);
    gm.gmshModelMeshFieldSetString(fld, "F", expr, &ierr);
    gm.gmshModelMeshFieldSetAsBackgroundMesh(fld, &ierr);
    gm.gmshOptionSetNumber("Mesh.MeshSizeExtendFromBoundary", 0, &ierr);
    gm.gmshOptionSetNumber("Mesh.MeshSizeFromPoints", 0, &ierr);
    gm.gmshOptionSetNumber("Mesh.MeshSizeFromCurvature", 0, &ierr);
    gm.gmshOptionSetNumber("Mesh.RandomSeed", 1, &ierr);
    gm.gmshOptionSetNumber("General.NumThreads", 1, &ierr);
    gm.gmshModelMeshGenerate(3, &ierr);
    if (ierr)
        return cf_error_set(err, CF_E_DATA, "box: Gmsh could not mesh it: %s",
                            gmsh_reason(why, sizeof why));
    return extract("box", 1, m, err);
}

/* The Gmsh part of cf_mesh_from_surface: the prepared surface s into the current model as one
** discrete surface, classified into patches (40 degrees), reparametrised, bounded into a volume and
** meshed at size h (file units). */
static cf_status fill_surface(const char *path, const cf_surface *s, double unit_mm, double h,
                              cf_mesh *m, cf_error *err)
{
    int ierr = 0, *dt = NULL;
    size_t ndt = 0;
    char why[300];
    size_t *tags = malloc(s->nv * sizeof *tags), *etags = malloc(s->nf * sizeof *etags),
           *conn = malloc(3 * s->nf * sizeof *conn);
    int *surf = NULL;
    cf_status st = CF_OK;
    if (!tags || !etags || !conn) {
        st = cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the surface", path);
        goto end;
    }
    for (size_t i = 0; i < s->nv; i++)
        tags[i] = i + 1;
    for (size_t t = 0; t < s->nf; t++) {
        etags[t] = t + 1;
        for (int k = 0; k < 3; k++)
            conn[3 * t + (size_t)k] = (size_t)s->tri[3 * t + (size_t)k] + 1;
    }
    gm.gmshModelAdd("surface", &ierr);
    int tag = gm.gmshModelAddDiscreteEntity(2, -1, NULL, 0, &ierr);
    gm.gmshModelMeshAddNodes(2, tag, tags, s->nv, s->X, 3 * s->nv, NULL, 0, &ierr);
    gm.gmshModelMeshAddElementsByType(tag, 2, etags, s->nf, conn, 3 * s->nf, &ierr);
    if (ierr)
        goto gmsh_failed;
    const double pi = 3.14159265358979323846;
    gm.gmshModelMeshClassifySurfaces(40 * pi / 180, 1, 1, pi, 0, &ierr);
    if (!ierr)
        gm.gmshModelMeshCreateGeometry(NULL, 0, &ierr);
    if (!ierr)
        gm.gmshModelGetEntities(&dt, &ndt, 2, &ierr);
    if (ierr || ndt == 0)
        goto gmsh_failed;
    surf = malloc(ndt / 2 * sizeof *surf);
    if (!surf) {
        st = cf_error_set(err, CF_E_INTERNAL, "%s: out of memory for the surface", path);
        goto end;
    }
    for (size_t k = 0; k < ndt / 2; k++)
        surf[k] = dt[2 * k + 1];
    int loop = gm.gmshModelGeoAddSurfaceLoop(surf, ndt / 2, -1, &ierr);
    if (!ierr)
        gm.gmshModelGeoAddVolume(&loop, 1, -1, &ierr);
    if (!ierr)
        gm.gmshModelGeoSynchronize(&ierr);
    if (ierr)
        goto gmsh_failed;
    gm.gmshOptionSetNumber("Mesh.MeshSizeMin", h, &ierr);
    gm.gmshOptionSetNumber("Mesh.MeshSizeMax", h, &ierr);
    gm.gmshOptionSetNumber("Mesh.RandomSeed", 1, &ierr);
    gm.gmshOptionSetNumber("General.NumThreads", 1, &ierr);
    gm.gmshModelMeshGenerate(3, &ierr);
    if (ierr) {
        st = cf_error_set(err, CF_E_DATA, "%s: Gmsh could not fill the surface with tetrahedra: "
                          "%s", path, gmsh_reason(why, sizeof why));
        goto end;
    }
    st = extract(path, unit_mm, m, err);
    goto end;
gmsh_failed:
    st = cf_error_set(err, CF_E_DATA, "%s: Gmsh could not make a geometry of the surface: %s",
                      path, gmsh_reason(why, sizeof why));
end:
    gm.gmshFree(dt);
    free(surf);
    free(tags);
    free(etags);
    free(conn);
    return st;
}


cf_status cf_mesh_from_surface(const char *path, double unit_mm, double size_mm,
                               const cf_mesh_limits *lim, cf_mesh *m,
                               cf_mesh_surface_info *info, cf_error *err)
{
    memset(m, 0, sizeof *m);
    const cf_mesh_limits dflt = cf_mesh_limits_default();
    if (!lim)
        lim = &dflt;
    cf_mesh_surface_info dummy;
    if (!info)
        info = &dummy;
    memset(info, 0, sizeof *info);
    if (!cf_surface_name(path))
        return cf_error_set(err, CF_E_DATA, "%s: not a surface file name: expected .obj or .stl",
                            path);
    if (!(unit_mm > 0) || !isfinite(unit_mm))
        return cf_error_set(err, CF_E_DATA, "%s: unit %g mm: must be finite and > 0", path, unit_mm);
    if (!(size_mm > 0) || !isfinite(size_mm))
        return cf_error_set(err, CF_E_DATA, "%s: element size %g mm: must be finite and > 0", path,
                            size_mm);
    cf_surface s;
    cf_status st = cf_surface_read(path, &s, err);
    if (st == CF_OK)
        st = cf_surface_prepare(&s, path, unit_mm, size_mm, info, err);
    if (st == CF_OK) { /* the fill's cost, before Gmsh starts (counted as cf_surface_prepare) */
        char what[120];
        snprintf(what, sizeof what, "filling it at an element size of %g mm", size_mm);
        st = mesh_cost(path, what, info->estimated_nodes, info->estimated_tets,
                       GMSH_FILL_TET_BYTES, lim, err);
    }
    if (st != CF_OK) {
        cf_surface_free(&s);
        return st;
    }
    const gmsh_job j = {path, unit_mm, 0, lim, &s, size_mm / unit_mm, NULL};
    st = gmsh_run(&j, m, err);
    cf_surface_free(&s);
    return st;
}
