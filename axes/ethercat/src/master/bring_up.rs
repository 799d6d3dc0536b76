//! Bring-up of the segment to OP, one function per AL state step: INIT → PRE-OP with the
//! identities checked, the PDO configuration in PRE-OP, PRE-OP → SAFE-OP → OP with distributed
//! clocks; then what OP runs on is read back (process image, SYNC0 grid, mailboxes).

use std::time::Duration;

use ethercrab::std::ethercat_now;
use ethercrab::subdevice_group::{DcConfiguration, PreOp};
use ethercrab::{
    DcSync, DefaultLock, MainDevice, MainDeviceConfig, PduRx, PduStorage, PduTx, RetryBehaviour,
    SubDeviceGroup, Timeouts,
};

use std::sync::Arc;

use super::al_state::read_al_status;
use super::bus::EthercatBus;
use super::carrier::carrier;
use super::dc::DcAlignment;
use super::error::{step, EthercatError};
use super::group::{OpGroup, MAX_PDI, MAX_SUBDEVICES};
use super::link::Link;
use super::mailbox::MailboxWatch;
use super::pdo_config::{configure_station, CycleTimeOutcome};
use super::process_image::ProcessImage;
use super::pump::{pump, Wire};
use super::refusal::{fitting_causes, BringUpWarning, RefusedSdo, StateRefusal};
use super::segment::{check_models, check_unit_pdo_limits, SegmentConfig, SegmentStation};
use super::worker::{Ethercrab, MailboxWorker, Shared};
use crate::identity::SubDeviceIdentity;
use crate::register::AlState;
use cellrt_cia402::bus::FrameCounters;
use cellrt_cia402::cycles::CycleTime;
use cellrt_cia402::mode::ModeOfOperation;
use cellrt_cia402::profiles::bring_up_causes;

/// Frames in flight during bring-up.
const MAX_FRAMES: usize = 16;
/// ethercrab's PDU storage element size.
const MAX_PDU_DATA: usize = PduStorage::element_size(1100);
/// Bytes of an Ethernet frame buffer (1514 without FCS, rounded up).
const FRAME_BUF: usize = 1536;
/// Retries of a bring-up PDU that timed out.
const BRINGUP_RETRIES: usize = 3;
/// How long bring-up waits for an SII EEPROM read (ethercrab's default is 10 ms; a host that
/// stalls for milliseconds — a virtual machine, a loaded emulator, a traced process — needs
/// more: 100 ms timed out under CI load with strace; bring-up only, so a missing EEPROM is
/// reported a second later at worst).
const BRINGUP_EEPROM_TIMEOUT: Duration = Duration::from_secs(1);
/// How long bring-up waits for a PDU's return (the cyclic exchange has its own frame timeout).
const BRINGUP_PDU_TIMEOUT: Duration = Duration::from_millis(100);
/// Delay from DC configuration to the first SYNC0 pulse.
const SYNC0_START_DELAY: Duration = Duration::from_millis(10);

/// The segment in PRE-OP, as ethercrab's INIT → PRE-OP leaves it.
pub(super) type PreOpGroup = SubDeviceGroup<MAX_SUBDEVICES, MAX_PDI, DefaultLock, PreOp>;

impl EthercatBus {
    /// Checks `config` against the models, then brings the segment on `link` to OP.
    pub fn bring_up(config: SegmentConfig, mut link: Box<dyn Link>) -> Result<Self, EthercatError> {
        check_models(&config)?;
        let plans = config.stations()?;
        check_unit_pdo_limits(&config, &plans)?;
        let (mut tx, mut rx, maindevice) = start_maindevice()?;
        let mut buf = vec![0u8; FRAME_BUF];
        let mut wire = Wire {
            tx: &mut tx,
            rx: &mut rx,
            link: link.as_mut(),
            buf: &mut buf,
        };
        let (group, names) = init_to_pre_op(&maindevice, &mut wire, &config, &plans)?;
        let setup = configure_pdos(&group, &maindevice, &mut wire, &config, &plans)?;
        let group =
            pre_op_to_op(group, &maindevice, &mut wire, config.cycle, &plans).map_err(|e| {
                let seen = SeenAtBringUp {
                    names: &names,
                    last_refused: &setup.last_refused,
                };
                explain_refusal(e, wire.link, wire.buf, &config, &plans, &seen)
            })?;
        let image = ProcessImage::read_back(&group, &maindevice, &mut wire, &config, &plans)?;
        let dc = DcAlignment::read_back(&group, &maindevice, &mut wire, &plans)?;
        let mailbox = MailboxWatch::read_back(&group, &maindevice, &mut wire, &plans)?;
        let mut station_addresses = Vec::with_capacity(plans.len());
        for position in 0..plans.len() {
            let sd = step("SubDevice lookup", group.subdevice(&maindevice, position))?;
            station_addresses.push(sd.configured_address());
        }
        let (carrier, carried) = carrier();
        let shared = Arc::new(Shared::new(image.axes.len(), plans.len()));
        let worker = MailboxWorker {
            ethercrab: Ethercrab {
                maindevice,
                group,
                tx,
                rx,
            },
            link: carried,
            frame: vec![0; FRAME_BUF],
            config: config.clone(),
            axes: image.axes.iter().map(|a| (a.station, a.slot)).collect(),
            station_addresses: station_addresses.clone(),
            sm1: mailbox.sm1.clone(),
            slots: mailbox.slots.clone(),
            shared,
            od_walk: None,
        }
        .spawn()
        .map_err(|e| EthercatError::Bringup {
            step: format!("mailbox worker thread: {e}"),
            source: ethercrab::error::Error::Internal,
        })?;
        Ok(EthercatBus {
            link,
            carrier,
            worker,
            config,
            axes: image.axes,
            stations: plans.len(),
            al_spans: vec![None; station_addresses.len()],
            al: vec![None; station_addresses.len()],
            station_addresses,
            pdi: vec![0; image.pdi_len],
            frame: buf,
            expected_wkc: image.expected_wkc,
            counters: FrameCounters::default(),
            index: 0,
            dc,
            dc_taken: 0,
            mailbox,
            warnings: setup.warnings,
        })
    }
}

/// ethercrab's PDU loop (its storage lives as long as the process) and the MainDevice with
/// cellrt's bring-up timeouts and retries.
pub(super) fn start_maindevice(
) -> Result<(PduTx<'static>, PduRx<'static>, MainDevice<'static>), EthercatError> {
    // Leaked on purpose: ethercrab 0.7's `PduStorage::try_split` takes `&'static self` and
    // `PduTx`/`PduRx`/`MainDevice<'static>` borrow it for as long as the bus runs (a `static`
    // could be split only once per process). One storage per bring-up, not per cycle.
    let storage: &'static PduStorage<MAX_FRAMES, MAX_PDU_DATA> =
        Box::leak(Box::new(PduStorage::new()));
    let (tx, rx, pdu_loop) = storage.try_split().map_err(|()| EthercatError::Bringup {
        step: "PDU storage".into(),
        source: ethercrab::error::Error::Internal,
    })?;
    let maindevice = MainDevice::new(
        pdu_loop,
        Timeouts {
            wait_loop_delay: Duration::from_micros(100),
            mailbox_response: Duration::from_millis(1000),
            mailbox_echo: Duration::from_millis(1000),
            eeprom: BRINGUP_EEPROM_TIMEOUT,
            pdu: BRINGUP_PDU_TIMEOUT,
            ..Timeouts::default()
        },
        MainDeviceConfig {
            dc_static_sync_iterations: 100,
            // A frame lost on the wire during bring-up is sent again.
            retry_behaviour: RetryBehaviour::Count(BRINGUP_RETRIES),
        },
    );
    Ok((tx, rx, maindevice))
}

/// What bring-up saw of each SubDevice that can explain a refusal later.
pub(super) struct SeenAtBringUp<'a> {
    /// Per SubDevice: its name from the SII.
    pub(super) names: &'a [String],
    /// Per SubDevice: the last SDO it refused (an optional setting skipped).
    pub(super) last_refused: &'a [Option<RefusedSdo>],
}

/// INIT → PRE-OP (ethercrab: addresses, SII, mailboxes), then the SubDevices found checked
/// against the stations planned: their number, each one's identity (1018h), and distributed
/// clocks in the ESC of each that is to run SYNC0. Returns the SubDevices' SII names too.
fn init_to_pre_op(
    maindevice: &MainDevice<'static>,
    wire: &mut Wire<'_>,
    config: &SegmentConfig,
    plans: &[SegmentStation],
) -> Result<(PreOpGroup, Vec<String>), EthercatError> {
    let group = wire.run(
        "bring-up to PRE-OP",
        maindevice.init_single_group::<MAX_SUBDEVICES, MAX_PDI>(ethercat_now),
    )?;
    let found = group.len();
    if found != plans.len() {
        return Err(EthercatError::Count {
            expected: plans.len(),
            found,
        });
    }
    for (position, (sd, plan)) in group.iter(maindevice).zip(plans).enumerate() {
        let d = &config.drives[plan.first_axis()];
        let id = sd.identity();
        let found = SubDeviceIdentity {
            vendor_id: id.vendor_id,
            product_code: id.product_id,
            revision: id.revision,
            serial: id.serial,
        };
        if !d.identity.matches(&found) {
            return Err(EthercatError::Identity {
                position,
                axis: d.axis.clone(),
                model: d.profile.model.as_str(),
                found_vendor: found.vendor_id,
                found_product: found.product_code,
                expected_vendor: d.identity.vendor_id,
                expected_product: d
                    .identity
                    .product_code
                    .map(|p| format!(", product {p:#010x}"))
                    .unwrap_or_default(),
            });
        }
        if plan.distributed_clocks && !sd.dc_support().any() {
            return Err(EthercatError::NoDistributedClocks {
                position,
                name: sd.name().to_string(),
                axis: d.axis.clone(),
            });
        }
    }
    let names = group
        .iter(maindevice)
        .map(|sd| sd.name().to_string())
        .collect();
    Ok((group, names))
}

/// What the PDO configuration leaves for later: the optional settings skipped (warnings) and,
/// per SubDevice, the last SDO it refused.
struct StationSetup {
    warnings: Vec<BringUpWarning>,
    last_refused: Vec<Option<RefusedSdo>>,
}

/// The PDO configuration of every station, in PRE-OP. A cycle time 1C32h:02 the drive does
/// not have or does not let be written is a warning where SYNC0 sets the cycle, an error where
/// the SubDevice runs free.
fn configure_pdos(
    group: &PreOpGroup,
    maindevice: &MainDevice<'static>,
    wire: &mut Wire<'_>,
    config: &SegmentConfig,
    plans: &[SegmentStation],
) -> Result<StationSetup, EthercatError> {
    let mut setup = StationSetup {
        warnings: Vec::new(),
        last_refused: vec![None; plans.len()],
    };
    for (position, plan) in plans.iter().enumerate() {
        let sd = step("SubDevice lookup", group.subdevice(maindevice, position))?;
        for drive in plan.slots.iter().flatten().map(|&a| &config.drives[a]) {
            for (k, sdo) in drive.startup_sdo.iter().enumerate() {
                let write = wire.run(format!("start-up SDO of axis '{}'", drive.axis), async {
                    Ok(super::sdo::expedited_download(&sd, sdo.index, sdo.sub, &sdo.data).await)
                })?;
                write.map_err(|e| EthercatError::StartupSdo {
                    position,
                    axis: drive.axis.clone(),
                    entry: k + 1,
                    object: format!("{:04X}h:{:02X}", sdo.index, sdo.sub),
                    value: sdo
                        .data
                        .iter()
                        .rev()
                        .fold(0u64, |v, b| v << 8 | u64::from(*b)),
                    code: super::refusal::abort_code(e),
                })?;
            }
        }
        let first = &config.drives[plan.first_axis()];
        let axis = &first.axis;
        let outcome = pump(
            configure_station(&sd, config, plan),
            wire.tx,
            wire.rx,
            wire.link,
            wire.buf,
        )
        .map_err(|source| {
            let causes: Vec<String> = fitting_causes(
                bring_up_causes(first.profile.model),
                0,
                &[first.mode],
                plan.distributed_clocks,
            )
            .iter()
            .map(|c| format!("{} ({})", c.cause, c.source))
            .collect();
            EthercatError::PdoConfiguration {
                position,
                axis: axis.clone(),
                source,
                causes: if causes.is_empty() {
                    String::new()
                } else {
                    format!("; likely cause: {}", causes.join("; or "))
                },
            }
        })?;
        let CycleTimeOutcome::Refused { read, sdo } = outcome else {
            continue;
        };
        let wanted = config.cycle.as_nanos() as u32;
        if !plan.distributed_clocks {
            return Err(EthercatError::CycleTimeNotSet {
                position,
                axis: axis.clone(),
                sdo,
                read,
                wanted,
            });
        }
        setup.last_refused[position] = Some(sdo);
        setup.warnings.push(BringUpWarning {
            position,
            axis: axis.clone(),
            sdo,
            read,
            wanted,
        });
    }
    Ok(setup)
}

/// PRE-OP → SAFE-OP → OP: SYNC0 at the cell's cycle time on every SubDevice configured for
/// distributed clocks; the others run free (SM2-synchronous). Without any, no DC set-up.
fn pre_op_to_op(
    mut group: PreOpGroup,
    maindevice: &MainDevice<'static>,
    wire: &mut Wire<'_>,
    cycle: CycleTime,
    plans: &[SegmentStation],
) -> Result<OpGroup, EthercatError> {
    for (mut sd, plan) in group.iter_mut(maindevice).zip(plans) {
        if plan.distributed_clocks {
            sd.set_dc_sync(DcSync::Sync0);
        }
    }
    if !plans.iter().any(|p| p.distributed_clocks) {
        let up = async {
            let g = group.into_pre_op_pdi(maindevice).await?;
            g.into_safe_op(maindevice).await?.into_op(maindevice).await
        };
        return wire.run("PRE-OP → SAFE-OP → OP", up).map(OpGroup::FreeRun);
    }
    let up = async {
        let g = group.into_pre_op_pdi(maindevice).await?;
        let g = g
            .configure_dc_sync(
                maindevice,
                DcConfiguration {
                    start_delay: SYNC0_START_DELAY,
                    sync0_period: cycle.as_duration(),
                    sync0_shift: Duration::ZERO,
                },
            )
            .await?;
        g.into_safe_op(maindevice).await?.into_op(maindevice).await
    };
    wire.run("PRE-OP → SAFE-OP → OP", up).map(OpGroup::Dc)
}

/// The error of a bring-up whose PRE-OP → SAFE-OP → OP did not complete, explained: the first
/// SubDevice whose AL status shows an error indication becomes a [`StateRefusal`]; where none
/// does (or its status cannot be read), `error` as it was.
fn explain_refusal(
    error: EthercatError,
    link: &mut dyn Link,
    frame: &mut [u8],
    config: &SegmentConfig,
    plans: &[SegmentStation],
    seen: &SeenAtBringUp<'_>,
) -> EthercatError {
    for (position, plan) in plans.iter().enumerate() {
        let Ok(status) = read_al_status(link, frame, position) else {
            return error;
        };
        if !status.error {
            continue;
        }
        let d = &config.drives[plan.first_axis()];
        let requested = match status.state {
            Some(AlState::Init) => "PRE-OP",
            Some(AlState::PreOp) => "SAFE-OP",
            _ => "OP",
        };
        let modes: Vec<ModeOfOperation> = plan
            .slots
            .iter()
            .flatten()
            .map(|&a| config.drives[a].mode)
            .collect();
        return EthercatError::StateRefused(Box::new(StateRefusal {
            position,
            name: seen.names.get(position).cloned().unwrap_or_default(),
            axis: d.axis.clone(),
            model: d.profile.model.as_str(),
            requested,
            state: status.state.map_or("no state", AlState::as_str),
            code: status.code,
            last_refused_sdo: seen.last_refused.get(position).copied().flatten(),
            causes: fitting_causes(
                bring_up_causes(d.profile.model),
                status.code,
                &modes,
                plan.distributed_clocks,
            ),
        }));
    }
    error
}
