/*
** VTK XML output of bodies (vtu.h). Every value written is finite: positions and strains of a
** solved body are (the solver refuses non-finite states), and anything else is written as 0.
*/
#include "report/vtu.h"

#include <math.h>
#include <stdio.h>

static double fin(double v)
{
    return isfinite(v) ? v : 0;
}

static void header(FILE *f, size_t points, size_t cells, const cf_vtu_state *s)
{
    fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
               "byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n<FieldData>\n"
               "<DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" "
               "format=\"ascii\">%.17g</DataArray>\n"
               "<DataArray type=\"Int64\" Name=\"step\" NumberOfTuples=\"1\" "
               "format=\"ascii\">%zu</DataArray>\n",
            fin(s->time), s->step);
    if (s->has_probe)
        fprintf(f, "<DataArray type=\"Float64\" Name=\"probe_depth_mm\" NumberOfTuples=\"1\" "
                   "format=\"ascii\">%.17g</DataArray>\n"
                   "<DataArray type=\"Float64\" Name=\"probe_force_N\" NumberOfTuples=\"1\" "
                   "format=\"ascii\">%.17g</DataArray>\n",
                fin(s->depth_mm), fin(s->force_N));
    fprintf(f, "</FieldData>\n<Piece NumberOfPoints=\"%zu\" NumberOfCells=\"%zu\">\n", points,
            cells);
}

/* A Float64 array of n tuples of nc components (v NULL: zeros), times scale. */
static void array(FILE *f, const char *name, int nc, size_t n, const double *v, double scale)
{
    fprintf(f, "<DataArray type=\"Float64\" Name=\"%s\" NumberOfComponents=\"%d\"", name, nc);
    if (nc == 6)
        fprintf(f, " ComponentName0=\"XX\" ComponentName1=\"YY\" ComponentName2=\"ZZ\" "
                   "ComponentName3=\"XY\" ComponentName4=\"YZ\" ComponentName5=\"XZ\"");
    fprintf(f, " format=\"ascii\">\n");
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < nc; k++)
            fprintf(f, "%.10g%c", v ? fin(scale * v[(size_t)nc * i + (size_t)k]) : 0.0,
                    k + 1 < nc ? ' ' : '\n');
    fprintf(f, "</DataArray>\n");
}

static void points(FILE *f, const cf_body *b, const double *x)
{
    fprintf(f, "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" "
               "format=\"ascii\">\n");
    for (size_t i = 0; i < b->nn; i++)
        fprintf(f, "%.12g %.12g %.12g\n", fin(x[3 * i]), fin(x[3 * i + 1]), fin(x[3 * i + 2]));
    fprintf(f, "</DataArray>\n</Points>\n");
}

static void cells(FILE *f, size_t count, int per, const uint32_t *conn, int vtk_type)
{
    fprintf(f, "<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for (size_t c = 0; c < count; c++) {
        for (int k = 0; k < per; k++)
            fprintf(f, "%u%c", conn[(size_t)per * c + (size_t)k], k + 1 < per ? ' ' : '\n');
    }
    fprintf(f, "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for (size_t c = 0; c < count; c++)
        fprintf(f, "%zu\n", (size_t)per * (c + 1));
    fprintf(f, "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for (size_t c = 0; c < count; c++)
        fprintf(f, "%d\n", vtk_type);
    fprintf(f, "</DataArray>\n</Cells>\n");
}

/* Each fibre group's reference direction per tetrahedron, "fibre_direction" (group 0) and
** "fibre_direction_K" (group K > 0), unit vectors of 3 components; nothing without fibres. */
static void fibre_arrays(FILE *f, const cf_body *b)
{
    for (size_t k = 0; k < b->nfibre; k++) {
        char name[48];
        if (k == 0)
            snprintf(name, sizeof name, "fibre_direction");
        else
            snprintf(name, sizeof name, "fibre_direction_%zu", k);
        fprintf(f, "<DataArray type=\"Float64\" Name=\"%s\" NumberOfComponents=\"3\" "
                   "format=\"ascii\">\n", name);
        for (size_t t = 0; t < b->nt; t++) {
            const double *a = b->fdir + 3 * (CF_FIBRE_MAX * t + k);
            fprintf(f, "%.10g %.10g %.10g\n", fin(a[0]), fin(a[1]), fin(a[2]));
        }
        fprintf(f, "</DataArray>\n");
    }
}

static void footer(FILE *f)
{
    fprintf(f, "</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
}

void cf_vtu_body(FILE *f, const cf_body *b, const cf_vtu_state *s)
{
    const cf_body_fields *q = s->fields;
    header(f, b->nn, b->nt, s);
    fprintf(f, "<PointData Vectors=\"displacement\" Tensors=\"stress_kPa\">\n"
               "<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" "
               "format=\"ascii\">\n");
    for (size_t i = 0; i < b->nn; i++)
        fprintf(f, "%.10g %.10g %.10g\n", fin(s->x[3 * i] - b->X[3 * i]),
                fin(s->x[3 * i + 1] - b->X[3 * i + 1]), fin(s->x[3 * i + 2] - b->X[3 * i + 2]));
    fprintf(f, "</DataArray>\n");
    array(f, "stress_kPa", 6, b->nn, q->node_stress, 1e3);
    array(f, "contact_force_N", 3, b->nn, s->contact, 1);
    array(f, "reaction_N", 3, b->nn, s->reaction, 1);
    fprintf(f, "</PointData>\n");
    points(f, b, s->x);
    cells(f, b->nt, 4, b->tet, 10); /* VTK_TETRA */
    fprintf(f, "<CellData Scalars=\"von_mises_kPa\" Tensors=\"stress_kPa\">\n");
    array(f, "stress_kPa", 6, b->nt, q->stress, 1e3);
    array(f, "von_mises_kPa", 1, b->nt, q->mises, 1e3);
    array(f, "strain_green_lagrange", 6, b->nt, q->strain, 1);
    array(f, "J", 1, b->nt, s->J, 1);
    fibre_arrays(f, b);
    fprintf(f, "</CellData>\n");
    footer(f);
}

void cf_vtu_springs(FILE *f, const cf_body *b, const cf_vtu_state *s)
{
    header(f, b->nn, b->ns, s);
    fprintf(f, "<PointData Vectors=\"displacement\">\n<DataArray type=\"Float64\" "
               "Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for (size_t i = 0; i < b->nn; i++)
        fprintf(f, "%.10g %.10g %.10g\n", fin(s->x[3 * i] - b->X[3 * i]),
                fin(s->x[3 * i + 1] - b->X[3 * i + 1]), fin(s->x[3 * i + 2] - b->X[3 * i + 2]));
    fprintf(f, "</DataArray>\n</PointData>\n");
    points(f, b, s->x);
    fprintf(f, "<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for (size_t k = 0; k < b->ns; k++)
        fprintf(f, "%u %u\n", b->si[k], b->sj[k]);
    fprintf(f, "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for (size_t k = 0; k < b->ns; k++)
        fprintf(f, "%zu\n", 2 * (k + 1));
    fprintf(f, "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for (size_t k = 0; k < b->ns; k++)
        fprintf(f, "3\n"); /* VTK_LINE */
    fprintf(f, "</DataArray>\n</Cells>\n<CellData Scalars=\"force_N\">\n");
    array(f, "force_N", 1, b->ns, s->fields->force, 1);
    array(f, "strain", 1, b->ns, s->strain, 1);
    fprintf(f, "<DataArray type=\"UInt8\" Name=\"solid\" format=\"ascii\">\n");
    for (size_t k = 0; k < b->ns; k++)
        fprintf(f, "%d\n", s->solid[k] ? 1 : 0);
    fprintf(f, "</DataArray>\n</CellData>\n");
    footer(f);
}

void cf_vtu_pvd(FILE *f, size_t count, const double *time, const char *what)
{
    fprintf(f, "<?xml version=\"1.0\"?>\n<!-- timestep: %s -->\n<VTKFile type=\"Collection\" "
               "version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n",
            what);
    for (size_t k = 0; k < count; k++) {
        fprintf(f, "<DataSet timestep=\"%.10g\" group=\"\" part=\"0\" file=\"body_%04zu.vtu\"/>\n",
                fin(time[k]), k);
        fprintf(f, "<DataSet timestep=\"%.10g\" group=\"\" part=\"1\" file=\"springs_%04zu.vtu\"/>\n",
                fin(time[k]), k);
    }
    fprintf(f, "</Collection>\n</VTKFile>\n");
}
