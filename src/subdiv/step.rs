//! One refinement step of any scheme on a topology: the dispatch between the primal schemes'
//! rules ([`Topo::refine_primal`]) and Doo–Sabin's dual step, kept apart from both so that
//! neither module needs the other.

use super::doo_sabin;
use super::topo::{Refined, Topo};
use super::Scheme;

/// One step of `scheme` on `t`: new points as stencils over the old ones, and the new faces.
pub(crate) fn refine_step(t: &Topo, scheme: Scheme) -> Refined {
    match scheme {
        Scheme::Loop | Scheme::CatmullClark => t.refine_primal(scheme),
        Scheme::DooSabin => doo_sabin::refine(t),
    }
}
