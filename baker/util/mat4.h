/*
 * 4x4 double matrices, column-major as glTF stores them (m[col*4 + row]), and the few
 * operations the loader needs: compose TRS, multiply, transform points and directions.
 */
#ifndef LMBAKE_MAT4_H
#define LMBAKE_MAT4_H

void lmb_mat4_identity(double m[16]);
/* out = a * b (out may alias neither) */
void lmb_mat4_mul(const double a[16], const double b[16], double out[16]);
/* T * R * S, rotation a unit quaternion (x, y, z, w) as in glTF */
void lmb_mat4_from_trs(const double t[3], const double q[4], const double s[3], double out[16]);
/* determinant of the upper 3x3: negative means the transform mirrors */
double lmb_mat4_det3(const double m[16]);
void lmb_mat4_point(const double m[16], const double p[3], double out[3]);
void lmb_mat4_vector(const double m[16], const double v[3], double out[3]);
int lmb_mat4_is_finite(const double m[16]);

#endif
