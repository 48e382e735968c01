/*
** VTK XML output of bodies (vtu.h). Every value written is finite: positions and strains of a
** solved body are (the solver refuses non-finite states), and anything else is written as 0.
*/
#include "report/vtu.h"

#include <math.h>

static double fin(double v)
{
    return isfinite(v) ? v : 0;
}

static void header(FILE *f, size_t points, size_t cells)
{
    fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
               "byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n"
               "<Piece NumberOfPoints=\"%zu\" NumberOfCells=\"%zu\">\n",
            points, cells);
}

static void points(FILE *f, const cf_body *b, const double *x)
{
    fprintf(f, "<PointData Vectors=\"displacement\">\n<DataArray type=\"Float64\" "
               "Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for (size_t i = 0; i < b->nn; i++)
        fprintf(f, "%.10g %.10g %.10g\n", fin(x[3 * i] - b->X[3 * i]),
                fin(x[3 * i + 1] - b->X[3 * i + 1]), fin(x[3 * i + 2] - b->X[3 * i + 2]));
    fprintf(f, "</DataArray>\n</PointData>\n<Points>\n<DataArray type=\"Float64\" "
               "NumberOfComponents=\"3\" format=\"ascii\">\n");
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

static void footer(FILE *f)
{
    fprintf(f, "</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
}

void cf_vtu_body(FILE *f, const cf_body *b, const double *x, const double *J)
{
    header(f, b->nn, b->nt);
    points(f, b, x);
    cells(f, b->nt, 4, b->tet, 10); /* VTK_TETRA */
    fprintf(f, "<CellData Scalars=\"J\">\n<DataArray type=\"Float64\" Name=\"J\" "
               "format=\"ascii\">\n");
    for (size_t t = 0; t < b->nt; t++)
        fprintf(f, "%.10g\n", fin(J[t]));
    fprintf(f, "</DataArray>\n</CellData>\n");
    footer(f);
}

void cf_vtu_springs(FILE *f, const cf_body *b, const double *x, const double *strain,
                    const unsigned char *solid)
{
    header(f, b->nn, b->ns);
    points(f, b, x);
    fprintf(f, "<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for (size_t s = 0; s < b->ns; s++)
        fprintf(f, "%u %u\n", b->si[s], b->sj[s]);
    fprintf(f, "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for (size_t s = 0; s < b->ns; s++)
        fprintf(f, "%zu\n", 2 * (s + 1));
    fprintf(f, "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for (size_t s = 0; s < b->ns; s++)
        fprintf(f, "3\n"); /* VTK_LINE */
    fprintf(f, "</DataArray>\n</Cells>\n");
    fprintf(f, "<CellData Scalars=\"strain\">\n<DataArray type=\"Float64\" Name=\"strain\" "
               "format=\"ascii\">\n");
    for (size_t s = 0; s < b->ns; s++)
        fprintf(f, "%.10g\n", fin(strain[s]));
    fprintf(f, "</DataArray>\n<DataArray type=\"UInt8\" Name=\"solid\" format=\"ascii\">\n");
    for (size_t s = 0; s < b->ns; s++)
        fprintf(f, "%d\n", solid[s] ? 1 : 0);
    fprintf(f, "</DataArray>\n</CellData>\n");
    footer(f);
}

void cf_vtu_pvd(FILE *f, size_t count, const double *depth)
{
    fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" "
               "byte_order=\"LittleEndian\">\n<Collection>\n");
    for (size_t k = 0; k < count; k++) {
        fprintf(f, "<DataSet timestep=\"%.10g\" group=\"\" part=\"0\" file=\"body_%04zu.vtu\"/>\n",
                fin(depth[k]), k);
        fprintf(f, "<DataSet timestep=\"%.10g\" group=\"\" part=\"1\" file=\"springs_%04zu.vtu\"/>\n",
                fin(depth[k]), k);
    }
    fprintf(f, "</Collection>\n</VTKFile>\n");
}
