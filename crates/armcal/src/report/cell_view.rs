//! A 3D view of the cell for the HTML report: robot capsules, obstacles, tracker and beam at
//! each planned pose, steppable pose by pose.
