/*
** The size of the lattice tangent's pattern (msm_tangent.c), read by the cost estimate of a scene
** (io/budget.c) so that the estimate follows the pattern.
*/
#ifndef CF_MODEL_MSM_TANGENT_H
#define CF_MODEL_MSM_TANGENT_H

/* A node couples with itself and at most 26 neighbours (a 3 x 3 x 3 block of nodes): a column of
** the tangent holds at most 3 CF_MSM_TANGENT_MAX_ADJ entries. */
#define CF_MSM_TANGENT_MAX_ADJ 27

#endif
