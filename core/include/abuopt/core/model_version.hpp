#pragma once
// Versions of the simulator's models, for the keys of stored results (docs/archive.md, "Model
// versions"). Raise one when a change moves that model's results beyond rounding: the startup-profile
// problem puts it into its identity, so an archive written before the change never answers for the
// new model (it is kept, under the old identity), while the results of the other models stay valid.

namespace abuopt {

// Hard ball-ball contact (abu.ball_contact: hard). 1: modes chosen by enumeration, a forced block
// released forward whatever margin crossed; 2: pivoting choice, a forced block released only in the
// direction whose margin crossed (docs/model.md 11.8); 3: gap events located by Newton on the
// Runge-Kutta solution to a derived tolerance instead of 2 ulp (docs/model.md 11.9); 4: a touching
// pair that separates is joined at an event only if its speeds agree to 1e-9 relative, not 1e-9
// absolute (the Zeno chatter of slow chains, docs/model.md 11.10); 5: a slipping cluster that
// reverses and back inside one step is stopped (its stop function's rate from the right-hand side
// in the dip check, docs/model.md 11.11); 6: under the PI drive with friction feedback each trial
// of the mode choice takes W' from the motor equation with its own modes, and a stop function that
// leaves zero into its side and is back across zero inside the first step after a release is
// stopped (the chatter of a setpoint step, docs/model.md 11.12).
inline constexpr int kContactModelVersion = 6;

}  // namespace abuopt
