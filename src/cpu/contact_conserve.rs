//! Pass `contact_conserve` of the contact between bodies (`contact_grad`
//! has the overview), after `g2p`: gives each field back the momentum the
//! interface's PIC share (`CONTACT_PIC_FRACTION`) took from it or gave it
//! (`ContactState::pic_dp`, summed in particle order), as one velocity
//! shift of all the field's particles. The blend acts on a few particles,
//! so unlike PIC over a whole body it does not conserve momentum by itself
//! (colliding disks drifted by 3.5 % of their impact momentum); the shift
//! restores it to round-off and leaves every relative motion as the blend
//! made it.
//! GPU twin: `shaders/contact_conserve.wgsl`.

use super::contact_detect::ContactState;
use crate::model::Contacts;
use rayon::prelude::*;

pub fn conserve(
    c: &Contacts,
    st: &mut ContactState,
    mass: &[f64],
    body: &[u32],
    v: &mut [[f64; 2]],
) {
    st.field_dp.fill([0.0; 3]);
    for ((dp, &m), &b) in st.pic_dp.iter().zip(mass).zip(body) {
        let f = &mut st.field_dp[c.field_of_body[b as usize] as usize];
        f[0] += m;
        f[1] += dp[0];
        f[2] += dp[1];
    }
    if st.field_dp.iter().all(|f| f[1] == 0.0 && f[2] == 0.0) {
        return;
    }
    let shift: &[[f64; 3]] = &st.field_dp;
    v.par_iter_mut()
        .zip(body.par_iter())
        .with_min_len(1024)
        .for_each(|(v, &b)| {
            let f = shift[c.field_of_body[b as usize] as usize];
            if f[0] > 0.0 {
                v[0] -= f[1] / f[0];
                v[1] -= f[2] / f[0];
            }
        });
}
