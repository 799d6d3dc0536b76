//! The homing start of every emulated drive (hm, 6060h = 6): what a Homing Operation Start
//! (Controlword bit 4 rising) does with the method in 6098h. A data-set method the model lists
//! sets home where the motor stands, without motion (MR-J3-T04 manual §8.11.3, §8.11.6; the
//! MR-JE-C's only method 37, MR-JE-C manual §7.3 6098h); a searching method the model lists
//! runs `motion::homing_search` where the drive may move; anything else is a homing error
//! (Statusword bit 13). Each model gives its lists as data.

use cellrt_cia402::profiles::homing_methods::{search, SearchRecipe};

/// CiA 402 method 37: homing on the current position (the MR-JE-C's default and only method).
pub const CURRENT_POSITION: i8 = 37;

/// What a Homing Operation Start does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HomingStart {
    /// Home where the motor stands, at once.
    SetHome,
    /// Run this search.
    Search(SearchRecipe),
    /// Homing error: the method is not listed, not emulated, or cannot run now.
    Error,
}

/// The homing methods of one model, as data.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HomingMethods<'a> {
    /// Every 6098h value the model's manual lists.
    pub listed: &'a [i8],
    /// The listed data-set methods (home on the current position).
    pub data_set: &'a [i8],
}

impl HomingMethods<'_> {
    /// The start of 6098h = `method`; `can_search`: the drive may move now (Operation enabled).
    pub fn start(&self, method: i64, can_search: bool) -> HomingStart {
        let Some(method) = i8::try_from(method)
            .ok()
            .filter(|m| self.listed.contains(m))
        else {
            return HomingStart::Error;
        };
        if self.data_set.contains(&method) {
            return HomingStart::SetHome;
        }
        match search(method).filter(|_| can_search) {
            Some(recipe) => HomingStart::Search(recipe),
            None => HomingStart::Error,
        }
    }
}
