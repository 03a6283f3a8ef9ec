//! Paper 000, Table 3: `R_r` from the dynamometer ratio `f_x` (eq. 11), as published.
//!
//! `R_r = sum_i a_i f_x^i`, `a_i = sum_k b_ki t_c^k`. The "up" row serves `t_c >= 0.08`, the
//! "down" row `t_c < 0.08` mm/tooth (the names are the paper's and refer to the feed range,
//! not the milling mode: the table is fitted for down milling with Table 2 coefficients).
//! Kept as the paper's reference; the estimator's own routes are the fitted `f_xt`
//! polynomial and the exact inversion.

/// `B[i][k]`: coefficient of `t_c^k` in `a_i`, for `t_c >= 0.08`.
const B_HIGH_TC: [[f32; 6]; 6] = [
    [1.0025, 3.4923, -11.623, 21.686, -20.461, 7.5984],
    [1.9136, -0.19059, -0.06742, 0.72142, -0.99634, 0.44387],
    [0.25847, -3.5744, 12.287, -23.303, 22.155, -8.2614],
    [-0.39152, -0.54253, 1.7496, -4.1310, 4.5050, -1.8290],
    [-0.21953, 0.16053, -4.1888, 9.6520, -9.7718, 3.7465],
    [-0.00415, -1.3243, 2.0759, -2.1582, 1.2153, -0.27103],
];

/// Same, for `t_c < 0.08`.
const B_LOW_TC: [[f32; 6]; 6] = [
    [0.48209, 35.217, -949.34, 15433.0, -131787.0, 453367.0],
    [1.6708, 18.147, -617.33, 10869.0, -96461.0, 339318.0],
    [0.69838, -27.238, 644.45, -9779.0, 80459.0, -270859.0],
    [-0.01002, -23.504, 641.61, -9802.3, 78650.0, -257044.0],
    [-0.03118, -24.362, 1024.9, -20092.0, 188567.0, -685683.0],
    [-0.32220, 22.946, -816.17, 14382.0, -127382.0, 447205.0],
];

/// Where the paper splits its two rows [mm/tooth].
pub const TC_SPLIT_MM: f32 = 0.08;

/// Which row to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Branch {
    /// The row the paper prescribes for this `t_c`.
    Auto,
    /// Force the `t_c >= 0.08` row ("up" in the paper).
    HighTc,
    /// Force the `t_c < 0.08` row ("down" in the paper).
    LowTc,
}

/// Evaluates eq. 11 with Table 3 (no clamping: callers flag and clamp).
pub fn rr_from_fx(fx: f32, tc_mm: f32, branch: Branch) -> f32 {
    let high = match branch {
        Branch::Auto => tc_mm >= TC_SPLIT_MM,
        Branch::HighTc => true,
        Branch::LowTc => false,
    };
    let b = if high { &B_HIGH_TC } else { &B_LOW_TC };
    let mut rr = 0.0;
    for row in b.iter().rev() {
        let mut ai = 0.0;
        for &bk in row.iter().rev() {
            ai = ai * tc_mm + bk;
        }
        rr = rr * fx + ai;
    }
    rr
}
