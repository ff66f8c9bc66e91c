def check(sdi, request)
    return "ok"
