//! The simulated drive's side of SLMP (MR-JE-C manual §2.4): 4020h object access (one
//! sub-index, or a block of consecutive sub-indexes from the given one to the object's last)
//! and 0101h model read. The "Number of data value" of an upload answer is the byte count of
//! the data (the manual leaves it open).

use std::time::Duration;

use super::{store, MrJeC, Refusal};
use cellrt_fieldbus::mr_je_c::objects::{object, ObjectId};
use cellrt_fieldbus::slmp::{Command, EndCode, Reply, Request, Response};

/// The drive's response to `request` at `now`; `out` holds the bytes an upload answer points
/// into.
pub fn answer<'b>(
    drive: &mut MrJeC,
    request: &Request<'_>,
    now: Duration,
    out: &'b mut Vec<u8>,
) -> Response<'b> {
    let result = match request.command {
        Command::Upload { index, sub } => drive.read(ObjectId::new(index, sub)).map(|v| {
            *out = v.to_le();
            Some((index, sub))
        }),
        Command::BlockUpload { index, sub } => block_upload(drive, index, sub, out).map(Some),
        Command::Download { index, sub, data } => drive
            .write_le(ObjectId::new(index, sub), data, now)
            .map(|()| None),
        Command::BlockDownload { index, sub, data } => {
            block_download(drive, index, sub, data, now).map(|()| None)
        }
        Command::ModelRead => Ok(None),
    };
    let reply = match (result, request.command) {
        (Err(r), _) => error(request, r.end_code()),
        (Ok(_), Command::ModelRead) => {
            let mut name = [b' '; 16];
            let model = drive.params().model.as_bytes();
            name[..model.len().min(16)].copy_from_slice(&model[..model.len().min(16)]);
            Reply::Model {
                name,
                code: drive.params().model_code,
            }
        }
        (Ok(Some((index, sub))), _) => Reply::Upload {
            index,
            sub,
            data: out,
        },
        (Ok(None), Command::Download { index, sub, data })
        | (Ok(None), Command::BlockDownload { index, sub, data }) => Reply::Download {
            index,
            sub,
            count: data.len() as u16,
        },
        (Ok(_), _) => error(request, EndCode::RequestIncorrect),
    };
    Response {
        subheader: request.subheader,
        route: request.route,
        reply,
    }
}

fn error(request: &Request<'_>, code: EndCode) -> Reply<'static> {
    let (command, sub) = request.command.codes();
    let refused = cellrt_fieldbus::slmp::SlmpError::Refused {
        code,
        subheader: request.subheader,
        route: request.route,
        command,
        sub,
    };
    refused
        .answer()
        .map(|r| r.reply)
        .unwrap_or(Reply::Error { code, info: [0; 9] })
}

fn block_upload(
    drive: &MrJeC,
    index: u16,
    sub: u8,
    out: &mut Vec<u8>,
) -> Result<(u16, u8), Refusal> {
    let sw = drive.params().software;
    store::row(ObjectId::new(index, sub), sw)?;
    let last = object(index, sw).map_or(sub, |o| o.last_sub(sw));
    out.clear();
    for k in sub..=last {
        out.extend(drive.read(ObjectId::new(index, k))?.to_le());
    }
    Ok((index, sub))
}

fn block_download(
    drive: &mut MrJeC,
    index: u16,
    sub: u8,
    mut data: &[u8],
    now: Duration,
) -> Result<(), Refusal> {
    let sw = drive.params().software;
    let mut k = sub;
    while !data.is_empty() {
        let row = store::row(ObjectId::new(index, k), sw).map_err(|r| match r {
            Refusal::NoSubIndex if k > sub => Refusal::TooLarge,
            r => r,
        })?;
        let n = row.ty.bytes();
        if data.len() < n {
            return Err(Refusal::SizeDiffers);
        }
        drive.write_le(ObjectId::new(index, k), &data[..n], now)?;
        data = &data[n..];
        k = k.checked_add(1).ok_or(Refusal::TooLarge)?;
    }
    Ok(())
}

/// The response frame to the SLMP frame `frame` received over `t` at `now` (none: the drive
/// stays silent, e.g. for a frame that is no SLMP request).
pub fn answer_frame(drive: &mut MrJeC, frame: &[u8], now: Duration) -> Option<Vec<u8>> {
    if !drive.serves(super::Transport::Slmp) {
        return None;
    }
    let mut buf = [0u8; cellrt_fieldbus::slmp::MAX_FRAME];
    let n = match cellrt_fieldbus::slmp::decode_request(frame) {
        Ok(request) => {
            drive.received(super::Transport::Slmp, now);
            let mut data = Vec::new();
            let response = answer(drive, &request, now, &mut data);
            cellrt_fieldbus::slmp::encode_response(&response, &mut buf).ok()?
        }
        Err(e) => {
            let response = e.answer()?;
            drive.received(super::Transport::Slmp, now);
            cellrt_fieldbus::slmp::encode_response(&response, &mut buf).ok()?
        }
    };
    Some(buf[..n].to_vec())
}
