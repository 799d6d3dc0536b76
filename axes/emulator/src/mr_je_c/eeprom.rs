//! The drive's EEPROM (MR-JE-C manual §7.2, §7.4.4, §7.4.5, front matter "EEPROM life"): the
//! parameters (2001h–27FFh) and point tables (2801h–28FFh) as last saved. A write through the
//! object dictionary changes only the RAM ("not by writing to the EEP-ROM immediately",
//! §7.4.4); Store parameters 1010h copies the RAM into the EEPROM, which takes time; the
//! EEPROM is loaded into the objects at the next power-on.

use std::collections::BTreeMap;
use std::time::Duration;

use super::store::Store;
use cellrt_fieldbus::mr_je_c::objects::ObjectId;
use cellrt_fieldbus::mr_je_c::value::Value;

/// The two parts 1010h saves separately (§7.4.4 table): sub 4 the parameters, sub 5 the point
/// tables, sub 1 both.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Region {
    /// Servo parameters, 2001h–27FFh.
    Parameters,
    /// Point tables, 2801h–28FFh.
    PointTables,
}

impl Region {
    /// The region object `index` belongs to, if any.
    pub const fn of(index: u16) -> Option<Region> {
        match index {
            0x2001..=0x27FF => Some(Region::Parameters),
            0x2801..=0x28FF => Some(Region::PointTables),
            _ => None,
        }
    }

    /// The regions a "save" to 1010h sub-index `sub` stores (§7.4.4 table: subs 2 and 3 store
    /// nothing).
    pub const fn saved_by(sub: u8) -> &'static [Region] {
        match sub {
            1 => &[Region::Parameters, Region::PointTables],
            4 => &[Region::Parameters],
            5 => &[Region::PointTables],
            _ => &[],
        }
    }
}

/// How long a save takes, per region saved (a named parameter of the emulated drive). The
/// manual gives only the whole: saving all "takes 10 seconds maximum" (§7.4.4). Our choice:
/// that maximum for sub 1, split by what is saved — the point tables (255 × 7 values) are
/// about four times the parameters (464 values): 2 s for the parameters, 8 s for the point
/// tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SaveTime {
    /// Time to save 2001h–27FFh (1010h:4).
    pub parameters: Duration,
    /// Time to save 2801h–28FFh (1010h:5).
    pub point_tables: Duration,
}

impl Default for SaveTime {
    fn default() -> Self {
        SaveTime {
            parameters: Duration::from_secs(2),
            point_tables: Duration::from_secs(8),
        }
    }
}

impl SaveTime {
    /// The time to save `regions` (saturating: any configured time is taken).
    pub fn of(&self, regions: &[Region]) -> Duration {
        regions
            .iter()
            .map(|r| match r {
                Region::Parameters => self.parameters,
                Region::PointTables => self.point_tables,
            })
            .fold(Duration::ZERO, Duration::saturating_add)
    }
}

/// What a write of a parameter or point table does while a save runs: the manual does not
/// say (a named parameter of the emulated drive).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum WriteDuringSave {
    /// Taken into the RAM as at any time; the running save stores the values it started with
    /// (the default: the cyclic link keeps writing its linked objects, 6083h and others).
    #[default]
    Accept,
    /// Refused as write-disabled in the present state (SLMP CCC9h, Modbus 02h).
    Refuse,
}

/// EEPROM writes so far, by region. The manual gives a life of 100 000 writes (front matter
/// "EEPROM life") but no object that counts them and no consequence of reaching it: the count
/// is the emulator's own, for tests, and nothing happens at any number.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct EepromWrites {
    /// Writes of the parameters: each save that stores them, each parameter set by
    /// commissioning ([`super::MrJeC::commission`]), each restore of their factory values.
    pub parameters: u64,
    /// Writes of the point tables: each save or restore of them.
    pub point_tables: u64,
}

impl EepromWrites {
    fn count(&mut self, region: Region) {
        let n = match region {
            Region::Parameters => &mut self.parameters,
            Region::PointTables => &mut self.point_tables,
        };
        *n = n.saturating_add(1);
    }
}

/// A save in progress: the values it started with, written when it ends.
#[derive(Debug, Clone)]
struct Saving {
    until: Duration,
    values: BTreeMap<ObjectId, Value>,
}

/// The EEPROM's contents and the save in progress.
#[derive(Debug, Clone)]
pub struct Eeprom {
    saved: BTreeMap<ObjectId, Value>,
    saving: Option<Saving>,
    writes: EepromWrites,
}

impl Eeprom {
    /// The factory contents: the parameters and point tables of `store` (a new drive's).
    pub fn factory(store: &Store) -> Eeprom {
        Eeprom {
            saved: region_values(store, &[Region::Parameters, Region::PointTables]).collect(),
            saving: None,
            writes: EepromWrites::default(),
        }
    }

    /// Whether a save runs at `now` (1010h bit 0 = 0, S_ERF off).
    pub fn saving(&self, now: Duration) -> bool {
        self.saving.as_ref().is_some_and(|s| now < s.until)
    }

    /// Starts saving `regions` of `store` at `now`, to end after `time`. The regions are
    /// counted as written at once (an interrupted save has written part of them).
    pub fn start(&mut self, store: &Store, regions: &[Region], now: Duration, time: Duration) {
        let values = region_values(store, regions).collect();
        for r in regions {
            self.writes.count(*r);
        }
        self.saving = Some(Saving {
            until: now.saturating_add(time),
            values,
        });
    }

    /// Ends a save whose time is up at `now`.
    pub fn advance(&mut self, now: Duration) {
        if self.saving.as_ref().is_some_and(|s| now >= s.until) {
            if let Some(s) = self.saving.take() {
                self.saved.extend(s.values);
            }
        }
    }

    /// The power goes off: a save still running is lost and the EEPROM keeps what it held
    /// before it (the manual only warns not to cut the power, §7.4.4; our choice).
    pub fn power_off(&mut self) {
        self.saving = None;
    }

    /// Writes one value at once (a parameter set by commissioning); a save running keeps it
    /// too, so its end does not put back the value it started with.
    pub fn write(&mut self, id: ObjectId, v: Value) {
        if let Some(r) = Region::of(id.index) {
            if let Some(held) = self.saving.as_mut().and_then(|s| s.values.get_mut(&id)) {
                *held = v.clone();
            }
            self.saved.insert(id, v);
            self.writes.count(r);
        }
    }

    /// Writes the factory values of `regions` from `factory` (1011h "load" at power-on).
    pub fn restore(&mut self, factory: &Store, regions: &[Region]) {
        self.saved.extend(region_values(factory, regions));
        for r in regions {
            self.writes.count(*r);
        }
    }

    /// Loads the EEPROM into `store` (power-on).
    pub fn load(&self, store: &mut Store) {
        for (id, v) in &self.saved {
            store.set(*id, v.clone());
        }
    }

    /// The writes so far.
    pub fn writes(&self) -> EepromWrites {
        self.writes
    }
}

fn region_values<'a>(
    store: &'a Store,
    regions: &'a [Region],
) -> impl Iterator<Item = (ObjectId, Value)> + 'a {
    store
        .iter()
        .filter(|(id, _)| Region::of(id.index).is_some_and(|r| regions.contains(&r)))
        .map(|(id, v)| (*id, v.clone()))
}
