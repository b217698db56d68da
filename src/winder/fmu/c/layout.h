/* The value references of winder's native FMU (Real in FMI 2.0, Float64 in FMI 3.0):
 * outputs [0, W_NOUT), inputs, parameters, the solver settings (rtol, atol, rk4_step), the
 * states (locals) and their derivatives (locals). FMI 3.0 adds, after VR_END: the time
 * (independent), the event indicators (locals) and the two Booleans (rk4, and a
 * single-drum scene's speed_profile), which FMI 2.0 numbers 0 and 1 among its Booleans.
 * winder.fmu.native numbers the variables of modelDescription.xml the same way. */
#ifndef WINDER_FMU_LAYOUT_H
#define WINDER_FMU_LAYOUT_H
#define VR_IN W_NOUT
#define VR_PAR (VR_IN + W_NIN)
#define VR_RTOL (VR_PAR + W_NPAR)
#define VR_ATOL (VR_RTOL + 1)
#define VR_HRK4 (VR_RTOL + 2)
#define VR_X (VR_RTOL + 3)
#define VR_DX (VR_X + W_N)
#define VR_END (VR_DX + W_N)
#define VR_TIME VR_END             /* FMI 3.0 only */
#define VR_Z (VR_TIME + 1)         /* FMI 3.0: the event indicators */
#define VR_BOOL (VR_Z + W_NZ)      /* FMI 3.0: rk4, then speed_profile */
#endif
