/* Daylight from published formulas: the Preetham, Shirley and Smits (1999)
 * analytic sky, and the sun's position for a place and a time (NOAA's solar
 * position algorithm, after Meeus).
 *
 * Units: the sky model gives luminance in cd/m^2; radiance here is
 * luminance / 179 (W/m^2/sr for white light, 179 lm/W, the efficacy that
 * Radiance and Cycles use), converted from the model's CIE xyY to linear
 * Rec. 709 RGB (the renderer's colour space). */
#ifndef ZT_LIGHT_SKY_MODEL_H
#define ZT_LIGHT_SKY_MODEL_H

#include "util/vec3.h"

/* Lumens per watt taken for the sky's white light. */
#define SKY_LUMINOUS_EFFICACY 179.0

typedef struct preetham_sky {
    double turbidity;   /* 1.7 .. 10 (the model's range; 2 very clear, 3 clear) */
    vec3 sun;           /* unit direction toward the sun, +y up */
    double theta_s;     /* the sun's zenith angle, radians */
    /* Zenith values and the Perez coefficients of Y, x, y (A..E each). */
    double zenith_Y, zenith_x, zenith_y; /* Y in cd/m^2 */
    double perez_Y[5], perez_x[5], perez_y[5];
} preetham_sky;

/* The model for turbidity t (clamped into 1.7 .. 10) and the sun's unit
 * direction (its elevation is clamped to >= 0: the model holds for a sun
 * above the horizon). */
void preetham_init(preetham_sky *s, double turbidity, vec3 sun);

/* Luminance (cd/m^2) and chromaticity of the sky in unit direction d;
 * below the horizon d is taken at the horizon. */
void preetham_xyY(const preetham_sky *s, vec3 d, double *x, double *y, double *Y);

/* Radiance (linear Rec. 709, W/m^2/sr per channel) in unit direction d. */
vec3 preetham_radiance(const preetham_sky *s, vec3 d);

/* CIE xyY -> linear Rec. 709 RGB (D65 white), unclamped. */
vec3 xyY_to_rec709(double x, double y, double Y);

/* A local date and time at a place. */
typedef struct solar_time {
    int year, month, day;     /* Gregorian calendar */
    double hour;              /* local clock time, 0 .. 24 (15.5 is 15:30) */
    double utc_offset;        /* hours east of UTC of the local clock (+2 for
                                 central European summer time) */
    double latitude;          /* degrees, north positive, -90 .. 90 */
    double longitude;         /* degrees, east positive, -180 .. 180 */
} solar_time;

/* The sun's elevation above the horizon and its azimuth (clockwise from
 * north, degrees: 90 east, 180 south), NOAA's algorithm without
 * atmospheric refraction. */
void solar_position(const solar_time *t, double *elevation_deg, double *azimuth_deg);

/* The unit direction toward the sun in scene coordinates (+y up) given the
 * scene's north (a direction, its horizontal part is used; east is
 * north x up, i.e. -z north puts east at +x). */
vec3 solar_direction(double elevation_deg, double azimuth_deg, vec3 north);

#endif
